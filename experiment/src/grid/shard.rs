//! Shards: a grid split among processes (`--shard I/N`), each running
//! runs I, I+N, I+2N, ... of the grid's fixed run order. Round-robin, so
//! that the costlier configurations spread evenly over the shards.

use std::fmt;
use std::str::FromStr;

/// The most shards a grid may be split into.
pub const MAX_SHARDS: usize = 1_000_000;

/// Shard `index` of `count` (`--shard INDEX/COUNT`, index from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    index: usize,
    count: usize,
}

impl Shard {
    /// The whole grid: shard 0 of 1.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Shard `index` of `count`; `index` must be below `count`, and `count`
    /// in [1, [`MAX_SHARDS`]].
    pub fn new(index: usize, count: usize) -> Result<Shard, String> {
        if !(1..=MAX_SHARDS).contains(&count) {
            return Err(format!("the shard count must be in [1, {MAX_SHARDS}], got {count}"));
        }
        if index >= count {
            return Err(format!(
                "shard {index}/{count}: the index counts from 0 and must be below the count {count}"
            ));
        }
        Ok(Shard { index, count })
    }

    /// The shard's index (from 0).
    pub fn index(self) -> usize {
        self.index
    }

    /// How many shards there are.
    pub fn count(self) -> usize {
        self.count
    }

    /// Whether the run at `position` of the run order is this shard's.
    pub fn takes(self, position: usize) -> bool {
        position % self.count == self.index
    }

    /// The same shard of a run order that continues one `before` runs long
    /// (a sweep's variants follow one another): position `p` here is
    /// position `before + p` of the whole order.
    pub fn after(self, before: usize) -> Shard {
        Shard {
            index: (self.index + self.count - before % self.count) % self.count,
            count: self.count,
        }
    }

    /// The items of `order` that are this shard's, in order.
    pub fn select<T: Copy>(self, order: &[T]) -> Vec<T> {
        order
            .iter()
            .enumerate()
            .filter(|(position, _)| self.takes(*position))
            .map(|(_, item)| *item)
            .collect()
    }
}

impl Default for Shard {
    fn default() -> Self {
        Shard::ALL
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(text: &str) -> Result<Shard, String> {
        let (index, count) = text
            .split_once('/')
            .ok_or_else(|| format!("{text:?} is not a shard INDEX/COUNT (e.g. 0/4)"))?;
        let number = |part: &str| {
            part.trim()
                .parse::<usize>()
                .map_err(|_| format!("{text:?} is not a shard INDEX/COUNT (e.g. 0/4): {part:?} is not a whole number"))
        };
        Shard::new(number(index)?, number(count)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_split_the_run_order_round_robin() {
        let order: Vec<usize> = (0..10).collect();
        let shards: Vec<Vec<usize>> = (0..3).map(|i| Shard::new(i, 3).unwrap().select(&order)).collect();
        assert_eq!(shards, vec![vec![0, 3, 6, 9], vec![1, 4, 7], vec![2, 5, 8]]);
        assert_eq!(Shard::ALL.select(&order), order);
    }

    #[test]
    fn a_shard_continues_across_consecutive_orders() {
        // Two orders of 4 and 5 runs, one after the other: the shard of the
        // second, shifted, takes the same positions as the shard of the whole.
        for count in 1..6 {
            for index in 0..count {
                let shard = Shard::new(index, count).unwrap();
                let whole: Vec<usize> = shard.select(&(0..9).collect::<Vec<_>>());
                let mut parts = shard.select(&(0..4).collect::<Vec<_>>());
                parts.extend(shard.after(4).select(&(4..9).collect::<Vec<_>>()));
                assert_eq!(parts, whole, "shard {shard}");
            }
        }
    }

    #[test]
    fn shards_parse_and_bad_ones_are_named() {
        assert_eq!("2/5".parse::<Shard>().unwrap(), Shard::new(2, 5).unwrap());
        assert_eq!("2/5".parse::<Shard>().unwrap().to_string(), "2/5");
        for (bad, says) in [
            ("5/5", "below the count"),
            ("0/0", "must be in [1,"),
            ("1", "INDEX/COUNT"),
            ("a/3", "\"a\" is not a whole number"),
            ("-1/3", "not a whole number"),
        ] {
            let err = bad.parse::<Shard>().unwrap_err();
            assert!(err.contains(says), "{bad}: {err}");
        }
    }
}
