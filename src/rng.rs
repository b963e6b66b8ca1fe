//! Random streams keyed by what they are for.
//!
//! Every random draw of the project comes from a stream derived from the
//! run's seed and a key naming its purpose (e.g. generation, network, trial),
//! never from which thread happens to run it, so results are bit-identical
//! for any thread count.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The random stream type used throughout (ChaCha8: stable across versions
/// and platforms, cheap to create).
pub type Stream = ChaCha8Rng;

/// SplitMix64's finaliser: a bijective mix of 64 bits.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The stream for `seed` and the key path `key` (e.g. `[PURPOSE, generation,
/// network, trial]`). Different keys give independent streams.
pub fn stream(seed: u64, key: &[u64]) -> Stream {
    let mut state = mix(seed);
    for &k in key {
        state = mix(state ^ mix(k));
    }
    let mut bytes = [0u8; 32];
    for (chunk, word) in bytes.chunks_mut(8).zip(expand(state)) {
        chunk.copy_from_slice(&word.to_le_bytes());
    }
    ChaCha8Rng::from_seed(bytes)
}

/// Four well-mixed words from one (never all zero, as `mix` is a bijection
/// of four distinct inputs): the seed of a 256-bit generator.
pub(crate) fn expand(seed: u64) -> [u64; 4] {
    [0, 1, 2, 3].map(|i| mix(seed.wrapping_add(i)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn streams_depend_on_seed_and_every_key_element() {
        let draw = |seed, key: &[u64]| stream(seed, key).random::<u64>();
        assert_eq!(draw(1, &[2, 3]), draw(1, &[2, 3]));
        assert_ne!(draw(1, &[2, 3]), draw(2, &[2, 3]));
        assert_ne!(draw(1, &[2, 3]), draw(1, &[3, 2]));
        assert_ne!(draw(1, &[2, 3]), draw(1, &[2, 3, 0]));
        assert_ne!(draw(1, &[]), draw(1, &[0]));
    }
}
