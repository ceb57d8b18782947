//! A traversal unit's free ray slots: which slot the top may give the next ray.
//!
//! Slots not used since reset are given in order (`fresh_slot` while `fresh_left`), then slots
//! given back, in the order they came back (a queue of them, `fifo`). The offer (`free_any`,
//! `free_idx`) is registered, a clock stale; the unit masks it for the clock after a take
//! (`just_alloc`), and the top takes only a slot it was offered.
//!
//! Why not the lowest free slot: a bit per slot and a priority encoder over the k bits (with the
//! take's one-hot decode into them) were the default core's slowest paths at seed 1 (7.66 and
//! 7.39 ns at k = 64). Here nothing is wider than a slot number. The queue empties with one
//! clock of reset and the fresh count restarts, so reset needs no pass over the slots. Which
//! slot a ray gets changes no result.

use super::fifo::fifo;
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// The offer and the count of slots holding a ray (for the outputs).
pub struct FreeList<'b> {
    pub free_any: S<'b>,
    pub free_idx: S<'b>,
    pub just_alloc: S<'b>,
    pub occupied: S<'b>,
}

/// The free list of `k` slots (`sb`-bit numbers): `alloc` takes the slot offered; `free_valid`
/// gives back `free_slot`.
pub fn free_list<'b>(
    b: &'b Builder,
    k: u32,
    sb: u32,
    alloc: S<'b>,
    free_valid: S<'b>,
    free_slot: S<'b>,
) -> FreeList<'b> {
    let fresh = b.reg("fresh_slot", Ty::u(sb), Some(0));
    let fresh_left = b.reg("fresh_left", Ty::BIT, Some(1));
    let from_fresh = (alloc & fresh_left).name("alloc_fresh");
    b.next(fresh, from_fresh.select(fresh + 1, fresh));
    let last_fresh = fresh.eq(k as i128 - 1).name("fresh_is_last");
    b.next(fresh_left, fresh_left & !(from_fresh & last_fresh));
    // The queue's head is offered once no fresh slot is left; `fresh_left` changes only with a
    // take, whose next offer is masked, so a take is from where the offer came.
    let pop = (alloc & !fresh_left).name("free_q_pop");
    let returned = fifo(b, "free_q", sb, k, free_valid, free_slot, pop);
    // Reset to what they hold after a clock of reset (slot 0 offered), so a core that idles for
    // a while after reset behaves as one that does not.
    let free_any = b.reg("free_any_r", Ty::BIT, Some(1));
    b.next(free_any, (fresh_left | returned.nonempty).name("free_any_c"));
    let free_idx = b.reg("free_idx_r", Ty::u(sb), Some(0));
    b.next(free_idx, fresh_left.select(fresh, returned.head).name("free_idx_c"));
    let just_alloc = b.reg("just_alloc", Ty::BIT, Some(0));
    b.next(just_alloc, alloc);
    let occupied = b.reg("occupied_r", Ty::u(sb + 1), Some(0));
    b.next(occupied, occupied + alloc.resize(sb + 1) - free_valid.resize(sb + 1));
    FreeList { free_any, free_idx, just_alloc, occupied }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;
    use std::collections::BTreeSet;

    /// A taker that takes most offers and gives held slots back at random, with a clock of
    /// reset (from a scrambled state) now and then: an offered slot is never one held, and
    /// once nothing has happened for a few clocks the offer is missing only when all k slots
    /// are held (none is lost, after reset too).
    #[test]
    fn offers_each_free_slot_once() {
        for k in [1u32, 5, 16, 64] {
            let sb = crate::scene::rom::rom_addr_bits(k as usize);
            let b = Builder::new("t");
            let (alloc, fv) = (b.input("alloc", Ty::BIT), b.input("free_valid", Ty::BIT));
            let f = free_list(&b, k, sb, alloc, fv, b.input("free_slot", Ty::u(sb)));
            b.output("has_free", f.free_any & !f.just_alloc);
            b.output("free_idx", f.free_idx);
            let m = b.finish();
            let mut sim = Sim::new(&m);
            let h = |i: usize| m.handle(m.inputs[i]);
            let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
            let (mut held, mut rng) = (BTreeSet::new(), crate::rng::SplitMix64(u64::from(k)));
            let (mut taken, mut quiet, mut dry) = (0u32, 0u32, 0u32);
            for cycle in 0..8000u32 {
                if cycle % 2000 == 1999 {
                    sim.scramble(u64::from(cycle));
                    sim.reset = true;
                    sim.tick();
                    sim.reset = false;
                    held.clear();
                    quiet = 0;
                }
                sim.eval();
                let (offered, slot) = (sim.get(out("has_free")) == 1, sim.get(out("free_idx")) as u32);
                if offered {
                    assert!(slot < k && !held.contains(&slot), "k {k} clock {cycle}: {slot} offered, {held:?} held");
                } else if quiet >= 4 {
                    assert_eq!(held.len(), k as usize, "k {k} clock {cycle}: no offer");
                    dry += 1;
                }
                let take = offered && rng.below(3) != 0;
                // Slower than the takes, so the list runs dry now and then.
                let give = !held.is_empty() && rng.below(6) == 0;
                let back = if give { *held.iter().nth(rng.below(held.len() as u64) as usize).unwrap() } else { 0 };
                if give {
                    held.remove(&back);
                }
                if take {
                    held.insert(slot);
                    taken += 1;
                }
                quiet = if take || give { 0 } else { quiet + 1 };
                for (i, v) in [take as i128, give as i128, back as i128].into_iter().enumerate() {
                    sim.set(h(i), v);
                }
                sim.tick();
            }
            assert!(taken > 400 && dry > 0, "k {k}: {taken} taken, {dry} clocks with every slot held");
        }
    }
}
