//! How a frame's rays are fed to the core: in which order (`feed_order`), and on which
//! cycles the source holds back although rays remain (`Stalls`). Both are seeded and
//! deterministic (SplitMix64, `crate::rng`), so every simulator — the Rust cycle and batched
//! simulators, GHDL, Icarus and Verilator — sees exactly the same stream, cycle for cycle.
//!
//! A core that keeps many rays in flight returns results out of order; feeding the rays
//! shuffled and with gaps checks that nothing depends on the results' order (results are
//! matched to rays by their id, `frame::mismatches`).

use crate::rng::SplitMix64;

/// The rays in the order the source offers them: unchanged without a seed, else a seeded
/// uniform permutation (Fisher–Yates with SplitMix64). The one place a frame is shuffled.
pub fn feed_order<T: Clone>(rays: &[T], seed: Option<u64>) -> Vec<T> {
    let mut v = rays.to_vec();
    if let Some(seed) = seed {
        let mut rng = SplitMix64(seed);
        for i in (1..v.len()).rev() {
            let j = rng.below(i as u64 + 1) as usize;
            v.swap(i, j);
        }
    }
    v
}

/// The rays of a `width`-pixel-wide frame (in any order; `pixel` gives a ray's pixel number) in tiles of `tile` ×
/// `tile` pixels, tile rows top to bottom, tiles left to right, pixel order within a tile: rays
/// that follow each other walk nearby nodes and triangles (what the caches of an
/// external-memory core live on, docs/MEMORY.md).
pub fn tile_order<T: Clone>(rays: &[T], pixel: impl Fn(&T) -> u32, width: u32, tile: u32) -> Vec<T> {
    let mut v = rays.to_vec();
    let tile = tile.max(1);
    v.sort_by_key(|r| {
        let (x, y) = (pixel(r) % width, pixel(r) / width);
        (y / tile, x / tile, y % tile, x % tile)
    });
    v
}

/// The source's stall pattern: on cycle c (counted from the first cycle the source may offer
/// a ray, the testbenches' cycle 0) it offers nothing — `ray_valid` low, even with rays left
/// and a ray on the data ports — iff `pattern[c mod PERIOD]`. The source may so drop
/// `ray_valid` before the core took the ray (stricter than AXI-Stream's rule for a source): a
/// ray is taken only on a cycle with `ray_valid` and `ray_ready` both high.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Stalls {
    /// Empty: never stalls; else `PERIOD` entries.
    pattern: Vec<bool>,
}

impl Stalls {
    /// Cycles after which the pattern repeats (a power of two: the harness's counter wraps).
    pub const PERIOD: usize = 4096;
    /// Bits of a cycle counter that wraps at `PERIOD`.
    pub const PERIOD_BITS: u32 = Self::PERIOD.trailing_zeros();
    /// The largest `percent` accepted: at 100 no ray would ever be offered.
    pub const MAX_PERCENT: u32 = 99;

    /// A source that offers a ray on every cycle it has one.
    pub fn none() -> Stalls {
        Stalls::default()
    }

    /// Exactly round(`percent` % of `PERIOD`) stall cycles per period, at positions chosen by
    /// a seeded partial Fisher–Yates shuffle (SplitMix64). `percent` must be at most
    /// `MAX_PERCENT`; 0 is `none()`.
    pub fn random(percent: u32, seed: u64) -> Stalls {
        assert!(percent <= Self::MAX_PERCENT, "stall percent {percent} > {}", Self::MAX_PERCENT);
        if percent == 0 {
            return Stalls::none();
        }
        let count = (Self::PERIOD * percent as usize + 50) / 100;
        let mut slots: Vec<usize> = (0..Self::PERIOD).collect();
        let mut rng = SplitMix64(seed);
        let mut pattern = vec![false; Self::PERIOD];
        for i in 0..count {
            let j = i + rng.below((Self::PERIOD - i) as u64) as usize;
            slots.swap(i, j);
            pattern[slots[i]] = true;
        }
        Stalls { pattern }
    }

    /// Stalls on the first `cycles` cycles of each period, in one block (a consumer away for a
    /// while: queues behind it fill up). At most `PERIOD` − 1.
    pub fn block(cycles: usize) -> Stalls {
        assert!(cycles < Self::PERIOD, "a stall block of {cycles} cycles");
        Stalls { pattern: (0..Self::PERIOD).map(|c| c < cycles).collect() }
    }

    /// Whether the source holds back on cycle `cycle`.
    pub fn at(&self, cycle: u64) -> bool {
        !self.pattern.is_empty() && self.pattern[(cycle % Self::PERIOD as u64) as usize]
    }

    pub fn is_none(&self) -> bool {
        self.pattern.is_empty()
    }

    /// The whole period (`PERIOD` entries; all false for `none()`).
    pub fn period(&self) -> Vec<bool> {
        (0..Self::PERIOD as u64).map(|c| self.at(c)).collect()
    }

    /// Stall cycles per period.
    pub fn per_period(&self) -> usize {
        self.pattern.iter().filter(|&&s| s).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_feed_order_is_a_seeded_permutation() {
        let rays: Vec<u32> = (0..1000).collect();
        assert_eq!(feed_order(&rays, None), rays);
        let a = feed_order(&rays, Some(7));
        assert_eq!(a, feed_order(&rays, Some(7)), "deterministic");
        assert_ne!(a, rays);
        assert_ne!(a, feed_order(&rays, Some(8)));
        let mut sorted = a.clone();
        sorted.sort();
        assert_eq!(sorted, rays, "a permutation");
        // Not a near-identity: most rays move.
        assert!(a.iter().zip(&rays).filter(|(x, y)| x != y).count() > 900);
        assert_eq!(feed_order::<u32>(&[], Some(1)), Vec::<u32>::new());
    }

    #[test]
    fn stalls_take_the_given_fraction_of_cycles() {
        assert!(Stalls::none().is_none() && !Stalls::none().at(5));
        assert_eq!(Stalls::random(0, 3), Stalls::none());
        for percent in [1, 25, 50, 99] {
            let s = Stalls::random(percent, 3);
            assert_eq!(s.per_period(), (Stalls::PERIOD * percent as usize + 50) / 100);
            assert_eq!(s, Stalls::random(percent, 3));
            assert_ne!(s, Stalls::random(percent, 4));
            assert_eq!(s.at(17), s.at(17 + Stalls::PERIOD as u64), "periodic");
        }
        // Spread out, not one block: both halves of the period get about half.
        let s = Stalls::random(50, 1);
        let first = s.period()[..Stalls::PERIOD / 2].iter().filter(|&&x| x).count();
        assert!((900..1150).contains(&first), "{first}");
        assert_eq!(1 << Stalls::PERIOD_BITS, Stalls::PERIOD);
    }
}
