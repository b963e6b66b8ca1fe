//! The genetic operators of ESP and the hill-climber, as in the ESP code of
//! Gomez & Miikkulainen.

use rand::RngExt;

use crate::rng::Stream;

/// The most draws [`cauchy`] makes before it gives up.
pub const MAX_CAUCHY_DRAWS: u32 = 10_000;

/// A Cauchy draw as in the ESP code: `alpha * tan(pi * u)`, `u` uniform in
/// (0, 1), drawn again while its magnitude exceeds `limit`.
///
/// A draw is accepted with probability `(2 / pi) atan(limit / alpha)`; the
/// settings' validation keeps it at 6 % or more
/// ([`MIN_CAUCHY_LIMIT_PER_SCALE`](super::MIN_CAUCHY_LIMIT_PER_SCALE)),
/// where [`MAX_CAUCHY_DRAWS`] rejections in a row have a probability below
/// 1e-280. Should they all be rejected all the same (a scale or limit that
/// was never validated, NaN), the draw is 0: it ends instead of looping
/// forever.
pub fn cauchy(rng: &mut Stream, alpha: f64, limit: f64) -> f64 {
    for _ in 0..MAX_CAUCHY_DRAWS {
        let u: f64 = rng.random();
        if u == 0.0 {
            continue;
        }
        let value = alpha * (std::f64::consts::PI * u).tan();
        if value.abs() <= limit {
            return value;
        }
    }
    0.0
}

/// One-point crossover with the cut at `cut` (0 <= cut < len): the first
/// child takes genes `[0, cut)` from `a` and the rest from `b`, the second
/// child the other way round.
pub fn crossover_at(a: &[f64], b: &[f64], cut: usize, first: &mut [f64], second: &mut [f64]) {
    first[..cut].copy_from_slice(&a[..cut]);
    first[cut..].copy_from_slice(&b[cut..]);
    second[..cut].copy_from_slice(&b[..cut]);
    second[cut..].copy_from_slice(&a[cut..]);
}

/// One-point crossover with the cut uniform over the genes.
pub fn crossover(rng: &mut Stream, a: &[f64], b: &[f64], first: &mut [f64], second: &mut [f64]) {
    let cut = rng.random_range(0..a.len());
    crossover_at(a, b, cut, first, second);
}

/// With probability `rate`, adds Cauchy noise to one uniformly chosen gene.
/// Returns the gene mutated, if any.
pub fn mutate_one_gene(rng: &mut Stream, genes: &mut [f64], rate: f64, alpha: f64, limit: f64) -> Option<usize> {
    if rng.random::<f64>() < rate {
        let k = rng.random_range(0..genes.len());
        genes[k] += cauchy(rng, alpha, limit);
        Some(k)
    } else {
        None
    }
}

/// Weights uniform in (-range, range).
pub fn random_genes(rng: &mut Stream, count: usize, range: f64) -> Vec<f64> {
    (0..count).map(|_| rng.random_range(-range..range)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    #[test]
    fn crossover_cuts_at_the_given_gene() {
        let a = [1.0, 2.0, 3.0, 4.0];
        let b = [10.0, 20.0, 30.0, 40.0];
        let (mut c, mut d) = ([0.0; 4], [0.0; 4]);
        crossover_at(&a, &b, 1, &mut c, &mut d);
        assert_eq!((c, d), ([1.0, 20.0, 30.0, 40.0], [10.0, 2.0, 3.0, 4.0]));
        crossover_at(&a, &b, 0, &mut c, &mut d);
        assert_eq!((c, d), (b, a));
        crossover_at(&a, &b, 3, &mut c, &mut d);
        assert_eq!((c, d), ([1.0, 2.0, 3.0, 40.0], [10.0, 20.0, 30.0, 4.0]));
    }

    #[test]
    fn crossover_cut_is_uniform_over_the_genes() {
        let mut rng = stream(1, &[]);
        let a = [1.0; 11];
        let b = [0.0; 11];
        let mut counts = [0usize; 11];
        let (mut c, mut d) = ([0.0; 11], [0.0; 11]);
        for _ in 0..22_000 {
            crossover(&mut rng, &a, &b, &mut c, &mut d);
            counts[c.iter().sum::<f64>() as usize] += 1;
        }
        // Each cut 0..=10 about 2000 times (sd about 43).
        assert!(counts.iter().all(|&n| (1800..2200).contains(&n)), "{counts:?}");
    }

    #[test]
    fn cauchy_draws_are_clipped_and_have_the_right_scale() {
        let mut rng = stream(2, &[]);
        let draws: Vec<f64> = (0..100_000).map(|_| cauchy(&mut rng, 0.3, 10.0)).collect();
        assert!(draws.iter().all(|x| x.abs() <= 10.0));
        // The median of |X| for a Cauchy of scale alpha is alpha.
        let mut abs: Vec<f64> = draws.iter().map(|x| x.abs()).collect();
        abs.sort_by(f64::total_cmp);
        let median = abs[abs.len() / 2];
        assert!((median - 0.3).abs() < 0.01, "median {median}");
        // Heavy tails survive up to the limit: some draws beyond 5.
        assert!(abs.iter().filter(|x| **x > 5.0).count() > 100);
        // A tight limit clips everything to it.
        assert!((0..1000).all(|_| cauchy(&mut rng, 1.0, 0.5).abs() <= 0.5));
    }

    const PINNED_ESP: [u64; 4] = [
        0xbfe2ce817d0aeead,
        0xbfca194e4e3e77aa,
        0xbfb3027906f54d41,
        0xc0143f74df9f69e2,
    ];
    const PINNED_HILL: [u64; 4] = [
        0xbfd6ede8b9f8799b,
        0xbfc404abfbd3ba09,
        0xbfdfe1726c7de656,
        0x3fe5f41f65c645ad,
    ];

    #[test]
    fn cauchy_draws_are_those_of_the_esp_code() {
        // Pinned: the draws of the default settings (ESP's 0.3 / 10, the
        // hill-climber's 1 / 10) must never change.
        let mut rng = stream(7, &[4, 2]);
        let esp: Vec<u64> = (0..4).map(|_| cauchy(&mut rng, 0.3, 10.0).to_bits()).collect();
        let hill: Vec<u64> = (0..4).map(|_| cauchy(&mut rng, 1.0, 10.0).to_bits()).collect();
        assert_eq!(esp, PINNED_ESP, "{esp:#x?}");
        assert_eq!(hill, PINNED_HILL, "{hill:#x?}");
    }

    #[test]
    fn a_cauchy_draw_ends_whatever_its_scale_and_limit() {
        let mut rng = stream(9, &[]);
        for (alpha, limit) in [(1e308, 1e-300), (f64::NAN, 10.0), (1.0, f64::NAN), (f64::INFINITY, 1.0)] {
            let value = cauchy(&mut rng, alpha, limit);
            assert!(value == 0.0 || value.abs() <= limit, "{alpha} {limit}: {value}");
        }
    }

    #[test]
    fn mutation_touches_one_gene_with_the_configured_probability() {
        let mut rng = stream(3, &[]);
        let mut mutated = 0;
        for _ in 0..20_000 {
            let mut genes = [0.0; 11];
            match mutate_one_gene(&mut rng, &mut genes, 0.4, 0.3, 10.0) {
                Some(k) => {
                    mutated += 1;
                    assert!(genes.iter().enumerate().all(|(i, g)| (i == k) == (*g != 0.0)));
                }
                None => assert_eq!(genes, [0.0; 11]),
            }
        }
        // 8000 expected, sd about 69.
        assert!((7700..8300).contains(&mutated), "{mutated}");
    }
}
