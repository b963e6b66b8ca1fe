//! A sub-population of ESP: neurons of equal length stored neuron after
//! neuron in one array, so that the whole sub-population is checked for
//! non-finite weights in one vectorised pass per generation and the
//! networks assembled from it need no check of their own; and the networks
//! a generation forms from the sub-populations, read in place.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::network::{Network, NetworkSet};
use crate::operators::random_genes;
use crate::rng::Stream;

/// `len()` neurons of `genes_per_neuron` genes each, neuron k at
/// `genes[k * per..(k + 1) * per]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Subpop {
    per: usize,
    genes: Vec<f64>,
}

impl Subpop {
    /// The sub-population of the given neurons, in order.
    ///
    /// # Panics
    /// If a neuron's length differs from `per`, or `per` is 0.
    pub fn from_neurons<N: AsRef<[f64]>>(per: usize, neurons: impl IntoIterator<Item = N>) -> Subpop {
        assert!(per > 0, "neurons have at least one gene");
        let mut genes = Vec::new();
        for neuron in neurons {
            assert_eq!(neuron.as_ref().len(), per, "neuron length");
            genes.extend_from_slice(neuron.as_ref());
        }
        Subpop { per, genes }
    }

    /// `size` neurons of `per` weights uniform in (-range, range), drawn
    /// neuron after neuron.
    pub fn random(rng: &mut Stream, size: usize, per: usize, range: f64) -> Subpop {
        Subpop::from_neurons(per, (0..size).map(|_| random_genes(rng, per, range)))
    }

    /// The number of neurons.
    pub fn len(&self) -> usize {
        self.genes.len() / self.per
    }

    /// Genes per neuron.
    pub fn genes_per_neuron(&self) -> usize {
        self.per
    }

    /// Whether the genes make whole neurons of at least one gene (a
    /// restored sub-population's check).
    pub fn is_whole(&self) -> bool {
        self.per > 0 && self.genes.len() % self.per == 0
    }

    /// Neuron `k`'s genes.
    pub fn neuron(&self, k: usize) -> &[f64] {
        &self.genes[k * self.per..(k + 1) * self.per]
    }

    /// Neuron `k`'s genes, to change them.
    pub fn neuron_mut(&mut self, k: usize) -> &mut [f64] {
        &mut self.genes[k * self.per..(k + 1) * self.per]
    }

    /// The neurons in order.
    #[cfg(test)]
    pub fn neurons(&self) -> std::slice::ChunksExact<'_, f64> {
        self.genes.chunks_exact(self.per)
    }

    /// The first non-finite weight, as (neuron, gene), if any: one
    /// vectorised pass over the whole sub-population when there is none.
    pub fn first_non_finite(&self) -> Option<(usize, usize)> {
        crate::network::first_non_finite(&self.genes).map(|i| (i / self.per, i % self.per))
    }

    /// Puts the neurons in the order `order`: neuron j becomes the old
    /// neuron `order[j]`.
    ///
    /// # Panics
    /// If `order` is not as long as the sub-population or names a neuron
    /// that does not exist.
    pub fn reorder(&mut self, order: &[usize]) {
        assert_eq!(order.len(), self.len(), "one position per neuron");
        let mut genes = Vec::with_capacity(self.genes.len());
        for &k in order {
            genes.extend_from_slice(self.neuron(k));
        }
        self.genes = genes;
    }
}

/// Which neuron of each sub-population every network of a generation
/// takes, network after network in one flat list: network j takes neuron
/// `flat[j * subpops + i]` of sub-population i.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Picks {
    pub(crate) subpops: usize,
    pub(crate) flat: Vec<usize>,
}

impl Picks {
    /// The number of networks.
    pub fn count(&self) -> usize {
        self.flat.len() / self.subpops
    }

    /// Each network's picks, one per sub-population.
    pub fn networks(&self) -> std::slice::ChunksExact<'_, usize> {
        self.flat.chunks_exact(self.subpops)
    }
}

/// A generation's networks as its sub-populations and picks: what the
/// evaluator reads, neuron by neuron, without a copy of each network.
pub(crate) struct Assembled<'a> {
    pub(crate) inputs: usize,
    pub(crate) outputs: usize,
    pub(crate) subpops: &'a [Subpop],
    pub(crate) picks: &'a Picks,
}

impl NetworkSet for Assembled<'_> {
    fn len(&self) -> usize {
        self.picks.count()
    }
    fn shape(&self, _: usize) -> (usize, usize) {
        (self.inputs, self.outputs)
    }
    fn hidden(&self, _: usize) -> usize {
        self.subpops.len()
    }
    fn neuron(&self, j: usize, k: usize) -> &[f64] {
        self.subpops[k].neuron(self.picks.flat[j * self.picks.subpops + k])
    }
    fn is_lesioned(&self, _: usize, _: usize) -> bool {
        false
    }
    fn network(&self, j: usize) -> Cow<'_, Network> {
        let genes = (0..self.subpops.len())
            .flat_map(|k| self.neuron(j, k))
            .copied()
            .collect();
        Cow::Owned(
            Network::from_genes(self.inputs, self.outputs, genes)
                .expect("the sub-populations' weights were checked finite and their shape fits"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neurons_are_stored_in_order_and_reordered_as_asked() {
        let mut subpop = Subpop::from_neurons(2, [[0.0, 0.5], [1.0, 1.5], [2.0, 2.5]]);
        assert_eq!((subpop.len(), subpop.genes_per_neuron()), (3, 2));
        assert_eq!(subpop.neuron(1), [1.0, 1.5]);
        subpop.neuron_mut(2)[1] = 9.0;
        subpop.reorder(&[2, 0, 1]);
        let neurons: Vec<&[f64]> = subpop.neurons().collect();
        assert_eq!(neurons, [&[2.0, 9.0][..], &[0.0, 0.5], &[1.0, 1.5]]);
        assert_eq!(subpop.first_non_finite(), None);
        subpop.neuron_mut(1)[1] = f64::NAN;
        assert_eq!(subpop.first_non_finite(), Some((1, 1)));
    }

    #[test]
    fn random_neurons_are_drawn_neuron_after_neuron() {
        let subpop = Subpop::random(&mut crate::rng::stream(4, &[]), 5, 3, 6.0);
        let mut rng = crate::rng::stream(4, &[]);
        for k in 0..5 {
            assert_eq!(subpop.neuron(k), random_genes(&mut rng, 3, 6.0).as_slice());
        }
        assert!(subpop.neurons().flatten().all(|w| w.abs() < 6.0));
    }
}
