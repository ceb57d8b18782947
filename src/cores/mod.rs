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
pub mod free_list;
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
mod traverse_entry;
mod traverse_leaf;
mod traverse_params;
mod traverse_retry;
mod traverse_stages;
pub mod tri_fetch;
pub mod wide_ram;

use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

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

/// Groups of `slot_bit_2`'s first clock for `k` bits (16 bits each): a copy of the early
/// slot register can serve each.
pub fn slot_bit_groups(k: u32) -> u32 {
    k.div_ceil(16)
}

/// Bit `slot` of the k-bit register `bits`, selected over two clocks: groups of 16 bits by the
/// slot's low bits from `early` into registers, then the group by the high bits of `late`
/// (`early` a clock later). A 128-to-1 select in one clock was the core's critical path, its
/// slot register placed across the die from the bits. The bit must not change in between (or
/// `bits` is the register's next value, read a clock before the register would be). `early`
/// holds copies of one slot number, dealt to the groups in turn (one register reaching every
/// group's select was a slowest path: `done_slot_r` → `done_has_g7`, 7.04 ns, 5.6 of it
/// routes).
pub fn slot_bit_2<'b>(b: &'b Builder, name: &str, bits: S<'b>, k: u32, early: &[S<'b>], late: S<'b>) -> S<'b> {
    let zero = b.konst(Ty::BIT, 0);
    let low = early[0].width().min(4);
    let groups: Vec<S> = (0..slot_bit_groups(k))
        .map(|g| {
            let cases: Vec<(u128, S)> = (0..16.min(k - 16 * g)).map(|i| (i as u128, bits.bit(16 * g + i))).collect();
            let early = early[g as usize % early.len()].slice(0, low);
            b.delay(&format!("{name}_g{g}"), b.case(early, &cases, zero).name(&format!("{name}_g{g}_c")))
        })
        .collect();
    if groups.len() == 1 {
        return groups[0];
    }
    let cases: Vec<(u128, S)> = groups.iter().enumerate().map(|(g, &x)| (g as u128, x)).collect();
    b.case(late.slice(4, late.width() - 4), &cases, zero).name(&format!("{name}_c"))
}
