//! Hardware cores: each builds its netlist from the parameters; its golden twin lives in
//! `model/`.

pub mod axi_read;
pub mod axis;
pub mod board;
pub mod brom;
pub mod cache;
pub mod checksum;
pub mod clock;
pub mod closest;
pub mod core_params;
pub mod cost;
pub mod divider;
pub mod fifo;
pub mod intersect;
pub mod leaf_stream;
pub mod memory_params;
pub mod mul;
pub mod plane;
pub mod ray_port;
pub mod raygen;
pub mod result_queue;
pub mod top;
pub mod top_memory;
pub mod traverse;
mod traverse_decide;
mod traverse_retry;
mod traverse_stages;
pub mod tri_fetch;
pub mod wide_ram;

use crate::rtl::build::S;

/// a < b (same type) as the sign of their difference one bit wider, which cannot overflow: one
/// carry chain whose last sum bit is the result, so a register or a LUT can take it straight
/// from the chain. Yosys builds `<` to end in the chain's carry-out, which nextpnr-ecp5 brings
/// out through a feed-out cell and then a LUT: on a 32-bit signed compare between registers
/// alone (LFE5U-85F, speed 6), 5.6 ns against 3.6 ns.
pub fn lt_chain<'b>(a: S<'b>, b: S<'b>) -> S<'b> {
    let w = a.width() + 1;
    (a.resize(w) - b.resize(w)).msb()
}

/// The `k`-bit one-hot decode of `x` (bit i set when x = i).
pub fn onehot<'b>(x: S<'b>, k: u32) -> S<'b> {
    let bits: Vec<S<'b>> = (0..k).rev().map(|i| x.eq(i as i128)).collect();
    x.b.cat(&bits)
}

/// Whether any of `bits` is set, and the index of the lowest set one (`idx_bits` wide): a tree
/// of log2(len) mux levels, not a priority chain.
pub fn lowest_set<'b>(bits: &[S<'b>], idx_bits: u32) -> (S<'b>, S<'b>) {
    let b = bits[0].b;
    let zero = b.konst(crate::rtl::Ty::BIT, 0);
    let mut level: Vec<(S<'b>, Option<S<'b>>)> = bits.iter().map(|&x| (x, None)).collect();
    let len = bits.len().next_power_of_two().max(2);
    level.resize(len, (zero, None));
    while level.len() > 1 {
        level = level
            .chunks(2)
            .map(|pair| {
                let ((lo_any, lo_idx), (hi_any, hi_idx)) = (pair[0], pair[1]);
                // The index below this level: the low half's when it has a set bit.
                let idx = match (lo_idx, hi_idx) {
                    (Some(l), Some(h)) => b.cat(&[!lo_any, lo_any.select(l, h)]),
                    _ => !lo_any,
                };
                (lo_any | hi_any, Some(idx))
            })
            .collect();
    }
    let (any, idx) = level[0];
    (any, idx.expect("two bits or more").resize(idx_bits))
}
