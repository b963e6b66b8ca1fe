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
    from_state(key_state(seed, key))
}

/// The state that `seed` and the key path `key` hash to.
fn key_state(seed: u64, key: &[u64]) -> u64 {
    key.iter().fold(mix(seed), |state, &k| step(state, k))
}

/// The key state after one more key element.
fn step(state: u64, k: u64) -> u64 {
    mix(state ^ mix(k))
}

/// The stream of a final key state.
fn from_state(state: u64) -> Stream {
    let mut bytes = [0u8; 32];
    for (chunk, word) in bytes.chunks_mut(8).zip(expand(state)) {
        chunk.copy_from_slice(&word.to_le_bytes());
    }
    ChaCha8Rng::from_seed(bytes)
}

/// The streams `stream(seed, [key.., j])` of every index `j`, with the
/// common part of their keys hashed once: how the algorithms hand an
/// evaluator the streams of a call's networks, which it makes as it needs
/// them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamFamily {
    state: u64,
}

impl StreamFamily {
    /// The family of `seed` and the key prefix `key`.
    pub fn new(seed: u64, key: &[u64]) -> StreamFamily {
        StreamFamily {
            state: key_state(seed, key),
        }
    }

    /// Member `j`: `stream(seed, [key.., j])`.
    pub fn stream(&self, j: usize) -> Stream {
        from_state(step(self.state, j as u64))
    }
}

/// Four well-mixed words from one (never all zero, as `mix` is a bijection
/// of four distinct inputs): the seed of a 256-bit generator, such as
/// the state of a noise generator keyed like the streams.
pub fn expand(seed: u64) -> [u64; 4] {
    [0, 1, 2, 3].map(|i| mix(seed.wrapping_add(i)))
}

/// A `u64` (a seed) written as a decimal string, read from a string or a
/// number: JSON tools that read numbers as doubles (jq, JavaScript,
/// Python's `float`) lose digits above 2^53. Use with
/// `#[serde(with = "esp_neuroevolution::rng::u64_string")]`.
pub mod u64_string {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `value` as a decimal string.
    pub fn serialize<S: Serializer>(value: &u64, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(value)
    }

    /// Reads a `u64` from a decimal string or a number.
    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<u64, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Either {
            Number(u64),
            Text(String),
        }
        match Either::deserialize(deserializer)? {
            Either::Number(n) => Ok(n),
            Either::Text(text) => text
                .parse()
                .map_err(|_| serde::de::Error::custom(format!("{text:?} is not a whole number in [0, 2^64)"))),
        }
    }
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

    #[test]
    fn a_family_member_is_the_stream_of_the_whole_key() {
        let family = StreamFamily::new(9, &[3, 4]);
        for j in [0, 1, 399, usize::MAX] {
            assert_eq!(family.stream(j), stream(9, &[3, 4, j as u64]));
        }
        assert_eq!(StreamFamily::new(9, &[]).stream(5), stream(9, &[5]));
    }
}
