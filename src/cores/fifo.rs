//! A first-word-fall-through FIFO in a RAM: the queues between the traversal units, the leaf
//! stream and the closest-hit unit (leaf entries, rays ready to enter a traversal ring, rays
//! done). Every queue of the core holds at most one entry per ray slot, so a depth of the slot
//! count never overflows and there is no `full` signal.
//!
//! A push is registered before it reaches the queue (the producers are logic far away on the
//! die, and the count's carry chain is the queue's own), so an entry pushed in cycle c is on
//! `head` from cycle c + 2. `head` is the oldest entry whenever `nonempty` is 1; `pop` (only
//! when nonempty) takes it, and the next one is on `head` in the next cycle. The RAM is read
//! synchronously (read-first) at both the read pointer and the one after it, and the registered
//! pop picks between the two words, so `head` is a RAM output register and a select; an entry
//! pushed into a queue that is empty (after this cycle's pop) is read in the same cycle it is
//! written, which a read-first RAM answers with the old word, so it comes from a copy of the
//! pushed word instead (`bypass`).

use super::wide_ram::{GROUP_BITS, NARROW_GROUP_BITS, WideRam};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

pub struct Fifo<'b> {
    pub head: S<'b>,
    pub nonempty: S<'b>,
}

/// A queue of `width`-bit entries, at least `depth` deep (a power of two).
pub fn fifo<'b>(b: &'b Builder, name: &str, width: u32, depth: u32, push: S<'b>, din: S<'b>, pop: S<'b>) -> Fifo<'b> {
    assert_eq!(din.width(), width, "{name}: entry width");
    let (heads, nonempty) = queue(b, name, depth, push, &[din], pop, (true, GROUP_BITS));
    Fifo { head: heads[0], nonempty }
}

/// `fifo` with its RAM in groups of at most `NARROW_GROUP_BITS` bits, each read at pointers of
/// its own: for a wide queue of a spread core, where a 16-bit group's pointer into its 16
/// LUT-RAM cells and the head's register was a slowest path (`wide_ram`).
pub fn narrow_fifo<'b>(b: &'b Builder, name: &str, depth: u32, push: S<'b>, din: S<'b>, pop: S<'b>) -> Fifo<'b> {
    let (heads, nonempty) = queue(b, name, depth, push, &[din], pop, (true, NARROW_GROUP_BITS));
    Fifo { head: heads[0], nonempty }
}

/// Splits a queue entry packed with `b.cat` (fields most significant first, of `widths`).
pub fn unpack<'b>(entry: S<'b>, widths: &[u32]) -> Vec<S<'b>> {
    let mut at = entry.width();
    widths
        .iter()
        .map(|&w| {
            at -= w;
            entry.slice(at, w)
        })
        .collect()
}

/// A queue whose entries are several words (each a RAM of its own, all at the same
/// pointers): for entries wider than a signal may be. The heads of the words, and `nonempty`;
/// `two_reads` as `queue`'s.
pub fn fifo_words<'b>(
    b: &'b Builder,
    name: &str,
    depth: u32,
    push: S<'b>,
    dins: &[S<'b>],
    pop: S<'b>,
    two_reads: bool,
) -> (Vec<S<'b>>, S<'b>) {
    queue(b, name, depth, push, dins, pop, (two_reads, GROUP_BITS))
}

/// The queue; with `two_reads` the RAM has two read ports and the pop picks after it (the
/// control queues and the result queue, in LUT RAM: the pop comes late, from a consumer), else
/// one read port at the next read pointer (half the RAM, the pop before the read: the AXI
/// read port's bookkeeping). With two reads the RAM is in groups of at most `group_bits`.
fn queue<'b>(
    b: &'b Builder,
    name: &str,
    depth: u32,
    push: S<'b>,
    dins: &[S<'b>],
    pop: S<'b>,
    (two_reads, group_bits): (bool, u32),
) -> (Vec<S<'b>>, S<'b>) {
    let push = b.valid_delay(&format!("{name}_push"), push);
    // The count's and flags' own copy: the push register also drives every LUT-RAM cell's
    // write enable, and through that net it was a slowest path into the count at seed 2 (a
    // leaf queue's, 7.45 ns).
    let push_ctl = b.copies(push, 1)[0];
    let depth = depth.next_power_of_two().max(2);
    let ab = depth.trailing_zeros();
    let wr = b.reg(&format!("{name}_wr"), Ty::u(ab), Some(0));
    let rd = b.reg(&format!("{name}_rd"), Ty::u(ab), Some(0));
    let count = b.reg(&format!("{name}_count"), Ty::u(ab + 1), Some(0));
    b.next(wr, push.select(wr + 1, wr));
    // rd + 1 is kept in a register of its own, so the RAM's read address is a select between
    // two registers rather than a carry chain: the address fans out to every LUT-RAM cell of a
    // wide queue, spread over tens of columns.
    let rd1 = b.reg(&format!("{name}_rd1"), Ty::u(ab), Some(1));
    let rd_next = pop.select(rd1, rd).name(&format!("{name}_rd_next"));
    b.next(rd, rd_next);
    b.next(rd1, pop.select(rd1 + 1, rd1));
    // The count after the push either way, each one adder from registers, and the pop (a
    // clock's late arrival, from the consumer's logic) picking one: with the pop through the
    // adder a queue's `nonempty` → its count was a slowest path at seed 2 (7.20 ns, 8 cells).
    let cw = ab + 1;
    let if_popped = (count - (!push_ctl).resize(cw)).name(&format!("{name}_count_if_pop"));
    let if_kept = (count + push_ctl.resize(cw)).name(&format!("{name}_count_if_kept"));
    b.next(count, pop.select(if_popped, if_kept).name(&format!("{name}_count_next")));
    // `bypass` and `nonempty` from compares of the count register, the pop one gate before
    // the flip-flop (through the subtractor and adder it was among the slowest paths).
    let (empty, one_left) = (count.eq(0), count.eq(1).name(&format!("{name}_one_left")));
    let drained = (empty | (one_left & pop)).name(&format!("{name}_drained"));
    let bypass = b.reg(&format!("{name}_bypass"), Ty::BIT, Some(0));
    b.next(bypass, (push_ctl & drained).name(&format!("{name}_bypass_c")));
    let popped = two_reads.then(|| b.valid_delay(&format!("{name}_popped"), pop));
    let nonempty = b.reg(&format!("{name}_nonempty"), Ty::BIT, Some(0));
    b.next(nonempty, (push_ctl | count.gt(1) | (one_left & !pop)).name(&format!("{name}_nonempty_c")));
    let one = dins.len() == 1;
    let heads = dins
        .iter()
        .enumerate()
        .map(|(k, &din)| {
            let word = |what: &str| if one { format!("{name}_{what}") } else { format!("{name}_{what}{k}") };
            let din = b.delay(&word("din"), din);
            // Both words the head may be next are read (two read ports, from registers); the
            // pop only picks one after the RAM. A read at `rd_next` put the pop's logic, the
            // address's fan-out and the LUT-RAM read on one path: the slowest of the queues.
            // The RAM is cut into groups of columns, each read at copies of the pointers of its
            // own (`wide_ram`).
            let q = if let Some(popped) = popped {
                let ram = WideRam::in_groups_of(b, &word("mem"), din.width(), depth as usize, group_bits);
                ram.write(b, &[push], &[wr], din);
                let (rds, rd1s) = pointer_copies(b, &word("rd"), [rd, rd1], pop, ram.groups());
                let q_stay = ram.read(b, &word("q_stay"), &rds);
                let q_next = ram.read(b, &word("q_next"), &rd1s);
                popped.select(q_next, q_stay)
            } else {
                let mem = b.ram(&word("mem"), din.width(), vec![0; depth as usize]);
                b.ram_write(mem, push, wr, din);
                b.read(&word("q"), mem, rd_next)
            };
            let din_r = b.reg(&word("din_r"), din.ty(), None);
            b.next_when(din_r, push, din);
            bypass.select(din_r, q).name(&word("head"))
        })
        .collect();
    (heads, nonempty)
}

/// The read pointers `rd`, `rd + 1` and `count − 1` more pairs that hold the same values, each
/// pair counting by itself with `pop` (a group of the RAM's columns is read at each pair). Not
/// copies of the registers (`Builder::copies`): those load the original's next value, a net
/// from the original's adder to every group across the die, which was a slowest path at seeds
/// 1 and 2 (a leaf queue's `rd1` back to its copies, 7.71 ns).
fn pointer_copies<'b>(
    b: &'b Builder,
    name: &str,
    [rd, rd1]: [S<'b>; 2],
    pop: S<'b>,
    count: usize,
) -> (Vec<S<'b>>, Vec<S<'b>>) {
    let (mut rds, mut rd1s) = (vec![rd], vec![rd1]);
    for g in 1..count {
        let r = b.reg(&format!("{name}_p{g}"), rd.ty(), Some(0));
        let r1 = b.reg(&format!("{name}1_p{g}"), rd.ty(), Some(1));
        b.next(r, pop.select(r1, r));
        b.next(r1, pop.select(r1 + 1, r1));
        rds.push(r);
        rd1s.push(r1);
    }
    (rds, rd1s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;
    use std::collections::VecDeque;

    /// Random pushes and pops (pops only when nonempty) against a VecDeque, cycle by cycle,
    /// including pushes into an empty queue while popping its last entry.
    #[test]
    fn behaves_like_a_queue() {
        let cases = [(2u32, true, GROUP_BITS), (4, true, GROUP_BITS), (16, true, GROUP_BITS), (16, true, 8)];
        for (depth, two_reads, group_bits) in cases.into_iter().chain([(4, false, GROUP_BITS), (16, false, GROUP_BITS)])
        {
            let b = Builder::new("t");
            let push = b.input("push", Ty::BIT);
            let din = b.input("din", Ty::u(40));
            let pop = b.input("pop", Ty::BIT);
            let (heads, nonempty) = queue(&b, "q", depth, push, &[din], pop, (two_reads, group_bits));
            b.output("head", heads[0]);
            b.output("nonempty", nonempty);
            let m = b.finish();
            let mut sim = Sim::new(&m);
            let h = |i: usize| m.handle(m.inputs[i]);
            let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
            let mut model = VecDeque::new();
            let mut in_flight = Vec::new();
            let mut x = 12345u32;
            let mut pushed = 0;
            for cycle in 0..4000 {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                assert_eq!(sim.get(out("nonempty")) == 1, !model.is_empty(), "depth {depth} cycle {cycle}");
                if let Some(&v) = model.front() {
                    assert_eq!(sim.get(out("head")), v, "depth {depth} cycle {cycle}");
                }
                let do_pop = !model.is_empty() && x & 3 != 0;
                let do_push = model.len() + in_flight.len() - (do_pop as usize) < depth as usize && x & 12 != 0;
                if do_pop {
                    model.pop_front();
                }
                // A push reaches the queue a clock later.
                model.extend(in_flight.drain(..));
                // Entries of 40 bits, so the RAM is three groups of columns (`wide_ram`), five of 8 bits.
                let entry = (pushed as i128 * 0x9e37_79b9_7f) & ((1 << 40) - 1);
                if do_push {
                    in_flight.push(entry);
                }
                sim.set(h(0), do_push as i128);
                sim.set(h(1), entry);
                sim.set(h(2), do_pop as i128);
                pushed += do_push as u32;
                sim.tick();
            }
            assert!(pushed > 1000);
        }
    }
}
