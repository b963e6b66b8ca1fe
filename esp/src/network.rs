//! The controller: a feed-forward network with one hidden layer of logistic
//! units, stored neuron-wise as ESP needs it.
//!
//! Each hidden neuron owns `inputs` input weights (the bias input included)
//! followed by `outputs` output weights: `inputs + outputs` genes (11 for a
//! 7-H-4 network). Outputs are logistic too, with no separate bias.
//! A lesioned hidden neuron contributes nothing to the outputs.

use std::borrow::{Borrow, Cow};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::math::{sigmoid_with, Exponential};

/// Errors building a network.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NetworkError {
    /// A size is zero or the genes do not fit the sizes.
    #[error("network shape: {0}")]
    Shape(String),
    /// An input or output slice of another length than the network's.
    #[error("the network has {expected} {what}, got {got}")]
    Length {
        /// "inputs" or "outputs".
        what: &'static str,
        /// The network's count.
        expected: usize,
        /// The slice's length.
        got: usize,
    },
    /// A weight is NaN or infinite.
    #[error("weight {index} of hidden neuron {neuron} is not finite ({value})")]
    NonFinite {
        /// Hidden neuron.
        neuron: usize,
        /// Gene index within the neuron.
        index: usize,
        /// The value.
        value: f64,
    },
}

/// The logistic sigmoid 1 / (1 + e^-x), with our own `exp` (the default
/// [`Exponential`]; see [`crate::math`]) so that every path computes the
/// same bits.
#[inline]
pub fn sigmoid(x: f64) -> f64 {
    crate::math::sigmoid(x)
}

/// Whether every weight is finite: one pass without early exit, which the
/// compiler vectorises.
fn all_finite(genes: &[f64]) -> bool {
    genes.iter().fold(true, |finite, v| finite & v.is_finite())
}

/// The index of the first non-finite weight, if any; a single vectorised
/// pass when there is none.
pub(crate) fn first_non_finite(genes: &[f64]) -> Option<usize> {
    if all_finite(genes) {
        return None;
    }
    genes.iter().position(|v| !v.is_finite())
}

pub(crate) fn check_sizes(inputs: usize, outputs: usize) -> Result<(), NetworkError> {
    if inputs == 0 || outputs == 0 {
        return Err(NetworkError::Shape(format!(
            "inputs and outputs must be >= 1, got {inputs} and {outputs}"
        )));
    }
    Ok(())
}

/// Networks read in place, neuron by neuron: a slice of [`Network`]s, or
/// ESP's sub-populations with the picks that form a generation's networks
/// from them, which an evaluator reads without a copy of each network
/// being made first.
pub trait NetworkSet: Sync {
    /// The number of networks.
    fn len(&self) -> usize;
    /// Whether there is none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Network `j`'s inputs (the bias input included) and outputs.
    fn shape(&self, j: usize) -> (usize, usize);
    /// Network `j`'s number of hidden neurons.
    fn hidden(&self, j: usize) -> usize;
    /// The genes of hidden neuron `k` of network `j`: input weights, then
    /// output weights.
    fn neuron(&self, j: usize, k: usize) -> &[f64];
    /// Whether hidden neuron `k` of network `j` is switched off.
    fn is_lesioned(&self, j: usize, k: usize) -> bool;
    /// Network `j` whole: borrowed from a set that stores it, assembled
    /// from any other.
    fn network(&self, j: usize) -> Cow<'_, Network>;
}

impl<N: Borrow<Network> + Sync> NetworkSet for [N] {
    fn len(&self) -> usize {
        <[N]>::len(self)
    }
    fn shape(&self, j: usize) -> (usize, usize) {
        let network = self[j].borrow();
        (network.inputs, network.outputs)
    }
    fn hidden(&self, j: usize) -> usize {
        self[j].borrow().hidden()
    }
    fn neuron(&self, j: usize, k: usize) -> &[f64] {
        self[j].borrow().neuron(k)
    }
    fn is_lesioned(&self, j: usize, k: usize) -> bool {
        self[j].borrow().is_lesioned(k)
    }
    fn network(&self, j: usize) -> Cow<'_, Network> {
        Cow::Borrowed(self[j].borrow())
    }
}

/// A 1-hidden-layer network; see the module docs for the gene layout.
///
/// Serde writes its sizes, genes and lesioned neurons, and checks them when
/// it reads one back (as [`Network::from_genes`] does).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "NetworkData")]
pub struct Network {
    inputs: usize,
    outputs: usize,
    genes: Vec<f64>,
    lesioned: Vec<bool>,
}

/// A network as serde reads it, before its check.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NetworkData {
    inputs: usize,
    outputs: usize,
    genes: Vec<f64>,
    lesioned: Vec<bool>,
}

impl TryFrom<NetworkData> for Network {
    type Error = NetworkError;

    fn try_from(data: NetworkData) -> Result<Network, NetworkError> {
        let mut network = Network::from_genes(data.inputs, data.outputs, data.genes)?;
        if data.lesioned.len() != network.hidden() {
            return Err(NetworkError::Shape(format!(
                "{} lesion flags for {} hidden neurons",
                data.lesioned.len(),
                network.hidden()
            )));
        }
        network.lesioned = data.lesioned;
        Ok(network)
    }
}

impl Network {
    /// A network from its hidden neurons' genes, one `Vec` per neuron.
    pub fn from_neurons(inputs: usize, outputs: usize, neurons: &[Vec<f64>]) -> Result<Network, NetworkError> {
        check_sizes(inputs, outputs)?;
        if let Some((k, n)) = neurons.iter().enumerate().find(|(_, n)| n.len() != inputs + outputs) {
            return Err(NetworkError::Shape(format!(
                "hidden neuron {k} has {} weights, expected {} ({inputs} inputs + {outputs} outputs)",
                n.len(),
                inputs + outputs
            )));
        }
        Network::from_genes(inputs, outputs, neurons.concat())
    }

    /// A network from all genes laid out neuron after neuron.
    pub fn from_genes(inputs: usize, outputs: usize, genes: Vec<f64>) -> Result<Network, NetworkError> {
        check_sizes(inputs, outputs)?;
        let per = inputs + outputs;
        if genes.is_empty() || genes.len() % per != 0 {
            return Err(NetworkError::Shape(format!(
                "{} weights do not make whole hidden neurons of {per} weights (at least one neuron)",
                genes.len()
            )));
        }
        if let Some(i) = first_non_finite(&genes) {
            return Err(NetworkError::NonFinite {
                neuron: i / per,
                index: i % per,
                value: genes[i],
            });
        }
        let hidden = genes.len() / per;
        Ok(Network {
            inputs,
            outputs,
            genes,
            lesioned: vec![false; hidden],
        })
    }

    /// Number of inputs (the bias input included).
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// Number of outputs.
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// Number of hidden neurons.
    pub fn hidden(&self) -> usize {
        self.lesioned.len()
    }

    /// Genes per hidden neuron: inputs + outputs.
    pub fn genes_per_neuron(&self) -> usize {
        self.inputs + self.outputs
    }

    /// All genes, neuron after neuron.
    pub fn genes(&self) -> &[f64] {
        &self.genes
    }

    /// The genes of hidden neuron `k`: input weights, then output weights.
    pub fn neuron(&self, k: usize) -> &[f64] {
        let per = self.genes_per_neuron();
        &self.genes[k * per..(k + 1) * per]
    }

    /// Switches hidden neuron `k` off (`true`) or on.
    pub fn set_lesioned(&mut self, k: usize, lesioned: bool) {
        self.lesioned[k] = lesioned;
    }

    /// Whether hidden neuron `k` is switched off.
    pub fn is_lesioned(&self, k: usize) -> bool {
        self.lesioned[k]
    }

    /// Computes the outputs for `input` into `output`; allocates nothing.
    ///
    /// The order of operations is part of the definition (a batched
    /// evaluator repeats it lane by lane with [`crate::math`]): each hidden
    /// unit starts at `w[0] x[0]` and adds `w[1] x[1]`, `w[2] x[2]`, ... one fused
    /// multiply-add at a time; each output starts at 0 and adds the hidden
    /// units' contributions in neuron order, also fused.
    ///
    /// # Panics
    /// If the slices' lengths differ from the network's inputs and outputs.
    #[inline(always)]
    pub fn activate(&self, input: &[f64], output: &mut [f64]) {
        self.activate_with(Exponential::default(), input, output);
    }

    /// [`Network::activate`], with an error instead of a panic when the
    /// slices' lengths differ from the network's inputs and outputs: what
    /// an evaluator that builds its inputs itself should call, so that a
    /// mistake there is a [`RunError::Evaluation`](crate::RunError::Evaluation)
    /// naming the lengths (through `?`) rather than a panic in every
    /// thread.
    pub fn try_activate(&self, input: &[f64], output: &mut [f64]) -> Result<(), NetworkError> {
        for (what, expected, got) in [
            ("inputs", self.inputs, input.len()),
            ("outputs", self.outputs, output.len()),
        ] {
            if expected != got {
                return Err(NetworkError::Length { what, expected, got });
            }
        }
        self.activate(input, output);
        Ok(())
    }

    /// [`Network::activate`] with the logistic units' exponential
    /// `exponential`.
    ///
    /// # Panics
    /// As [`Network::activate`].
    #[inline(always)]
    pub fn activate_with(&self, exponential: Exponential, input: &[f64], output: &mut [f64]) {
        assert_eq!(input.len(), self.inputs, "input length");
        assert_eq!(output.len(), self.outputs, "output length");
        output.fill(0.0);
        let per = self.genes_per_neuron();
        for (neuron, &lesioned) in self.genes.chunks_exact(per).zip(&self.lesioned) {
            if lesioned {
                continue;
            }
            let (w_in, w_out) = neuron.split_at(self.inputs);
            let mut activation = w_in[0] * input[0];
            for (w, x) in w_in.iter().zip(input).skip(1) {
                activation = w.mul_add(*x, activation);
            }
            let h = sigmoid_with(activation, exponential);
            for (o, w) in output.iter_mut().zip(w_out) {
                *o = h.mul_add(*w, *o);
            }
        }
        for o in output.iter_mut() {
            *o = sigmoid_with(*o, exponential);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn activation_matches_a_hand_computation() {
        // 2 inputs (x, bias), 1 output, 2 hidden neurons.
        let net = Network::from_neurons(2, 1, &[vec![1.0, -1.0, 2.0], vec![0.5, 0.0, -3.0]]).unwrap();
        let mut out = [0.0];
        net.activate(&[2.0, 1.0], &mut out);
        // Each output adds its hidden units' contributions with fused multiply-adds.
        let h = sigmoid(1.0);
        let expected = sigmoid(h.mul_add(-3.0, 2.0 * h));
        assert_eq!(out[0], expected);
    }

    #[test]
    fn a_lesioned_neuron_contributes_nothing() {
        let mut net = Network::from_neurons(2, 1, &[vec![1.0, -1.0, 2.0], vec![0.5, 0.0, -3.0]]).unwrap();
        net.set_lesioned(1, true);
        let mut out = [0.0];
        net.activate(&[2.0, 1.0], &mut out);
        assert_eq!(out[0], sigmoid(2.0 * sigmoid(1.0)));
        let alone = Network::from_neurons(2, 1, &[vec![1.0, -1.0, 2.0]]).unwrap();
        let mut out2 = [0.0];
        alone.activate(&[2.0, 1.0], &mut out2);
        assert_eq!(out, out2);
    }

    #[test]
    fn bad_shapes_and_weights_are_refused() {
        assert!(Network::from_genes(7, 4, vec![]).is_err());
        assert!(Network::from_genes(7, 4, vec![0.0; 12]).is_err());
        assert!(Network::from_neurons(7, 4, &[vec![0.0; 11], vec![0.0; 10]]).is_err());
        let err = Network::from_genes(7, 4, [vec![0.0; 13], vec![f64::NAN], vec![0.0; 8]].concat()).unwrap_err();
        assert_eq!(err.to_string(), "weight 2 of hidden neuron 1 is not finite (NaN)");
    }
}
