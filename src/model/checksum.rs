//! The frame checksum the board tops show (docs/BOARDS.md): the golden twin of
//! `cores::checksum`. Each result is packed into 32-bit words and mixed to one word by
//! add-rotate-xor rounds (Speck's round function, with the words as round keys); the frame's
//! checksum is the sum of its results' mixes modulo 2^32, so it does not depend on the order
//! the results come out in — the core finishes rays out of order.

use crate::model::golden::Hit;

/// The two 32-bit words a mix starts from (digits of the golden ratio and of π: nothing up
/// the sleeve).
pub const START: (u32, u32) = (0x9E37_79B9, 0x243F_6A88);

/// Round keys after the result's own words: every bit of the last word still reaches every
/// bit of the mix.
pub const FINAL_KEYS: [u32; 2] = [0xB7E1_5162, 0x8AED_2A6A];

/// Widths of the core's result fields, as its `res_*` ports have them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResultWidths {
    pub id: u32,
    pub tri: u32,
    pub t: u32,
    pub u: u32,
    pub v: u32,
}

impl ResultWidths {
    /// Bits of a packed result: hit, id, tri, t, u, v.
    pub fn bits(&self) -> u32 {
        1 + self.id + self.tri + self.t + self.u + self.v
    }

    /// Words of a packed result.
    pub fn words(&self) -> u32 {
        self.bits().div_ceil(32)
    }
}

/// One Speck round on (x, y) with round key `k`.
pub fn round((x, y): (u32, u32), k: u32) -> (u32, u32) {
    let x = x.rotate_right(8).wrapping_add(y) ^ k;
    (x, y.rotate_left(3) ^ x)
}

/// A result's fields packed least significant first — hit, id, tri, t, u, v, each in its
/// port's width (two's complement for t, u, v) — into 32-bit words. A miss packs as hit 0 and
/// its id: the core's other fields are not defined for a miss.
pub fn pack(w: &ResultWidths, id: u64, hit: Option<Hit>) -> Vec<u32> {
    let (h, tri, t, u, v) = match hit {
        Some(x) => (1, x.tri as u128, x.t as u128, x.u as u128, x.v as u128),
        None => (0, 0, 0, 0, 0),
    };
    let fields = [(h, 1), (id as u128, w.id), (tri, w.tri), (t, w.t), (u, w.u), (v, w.v)];
    let mut words = vec![0u32; w.words() as usize];
    let mut at = 0u32;
    for (value, width) in fields {
        for k in 0..width {
            if (value >> k) & 1 == 1 {
                words[((at + k) / 32) as usize] |= 1 << ((at + k) % 32);
            }
        }
        at += width;
    }
    words
}

/// The mix of one result: its words, then `FINAL_KEYS`, as round keys from `START`; the
/// second word of the state.
pub fn mix(words: &[u32]) -> u32 {
    words.iter().chain(&FINAL_KEYS).fold(START, |s, &k| round(s, k)).1
}

/// The checksum of a frame's results (any order).
pub fn frame_checksum(w: &ResultWidths, results: impl IntoIterator<Item = (u64, Option<Hit>)>) -> u32 {
    results.into_iter().fold(0u32, |acc, (id, hit)| acc.wrapping_add(mix(&pack(w, id, hit))))
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: ResultWidths = ResultWidths { id: 20, tri: 14, t: 32, u: 32, v: 32 };

    #[test]
    fn packs_fields_least_significant_first() {
        let words = pack(&W, 5, Some(Hit { tri: 3, t: -1, u: 2, v: 0 }));
        assert_eq!(words.len(), 5, "131 bits");
        // hit at bit 0, id from bit 1, tri from bit 21, t (all ones) from bit 35 to 66, u from 67.
        assert_eq!(words, vec![1 | 5 << 1 | 3 << 21, 0xFFFF_FFF8, 0b111 | 2 << 3, 0, 0]);
        assert_eq!(pack(&W, 5, None), vec![5 << 1, 0, 0, 0, 0], "a miss: hit 0 and the id only");
    }

    #[test]
    fn every_field_changes_the_mix_and_order_does_not_change_the_sum() {
        let a = (7u64, Some(Hit { tri: 9, t: 1000, u: 5, v: 6 }));
        let base = mix(&pack(&W, a.0, a.1));
        let h = a.1.unwrap();
        for other in [
            (8, a.1),
            (7, None),
            (7, Some(Hit { tri: 8, ..h })),
            (7, Some(Hit { t: 1001, ..h })),
            (7, Some(Hit { u: 4, ..h })),
            (7, Some(Hit { v: -6, ..h })),
        ] {
            assert_ne!(mix(&pack(&W, other.0, other.1)), base, "{other:?}");
        }
        let b = (3u64, None);
        assert_eq!(frame_checksum(&W, [a, b]), frame_checksum(&W, [b, a]));
        assert_eq!(frame_checksum(&W, [a, b]), base.wrapping_add(mix(&pack(&W, 3, None))));
    }
}
