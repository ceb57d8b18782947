//! The traversal unit's entry stage E (`traverse.rs` says what the unit does): the queues of
//! rays back from a leaf (unparked) and of new rays, and the choice of one to enter the ring
//! when the token in G will not return.

use super::fifo::fifo;
use super::traverse_stages::{Queued, Retried, RetryQueue, Unit};
use crate::rtl::Ty;
use crate::rtl::build::S;

impl<'b> Unit<'b> {
    /// The queues into the ring: rays back from a leaf (slot, sp) and new rays (slot, tmax,
    /// miss).
    pub(super) fn queues(&self) -> Queued<'b> {
        let (b, k, sb, spw, dist, inp) = (self.b, self.p.slots, self.sb, self.spw, self.dist, &self.inp);
        b.stage("queues", "E: rays back from a leaf and new rays wait; one enters when no token returns");
        let ring_g_valid = b.wire("ring_g_valid", Ty::BIT);
        let unpark_pop = b.wire("unpark_pop", Ty::BIT);
        let new_pop = b.wire("new_pop", Ty::BIT);
        // An unparked ray's entry: slot, stack pointer, and whether that is 0 (made here, so
        // that E's done bit after the head's selects is one gate: `unpark_q_popped` → `q_done`
        // through the compare was 7.02 ns at a seed).
        // In a spread core the entry holds sp − 1 as well: the head's select, the subtract and
        // the ring's select into the stack's read address were a slowest path of the fitted
        // core at seed 1 (`unpark_q_popped` → `stack_raddr`, 7.10 ns).
        let merge_sp_m1 = self.p.spread.then(|| (inp.merge_sp - 1).name("merge_sp_m1"));
        let mut unpark_fields = vec![inp.merge_slot, inp.merge_sp, inp.merge_sp.eq(0).name("merge_sp_zero")];
        unpark_fields.extend(merge_sp_m1);
        let unpark_in = b.cat(&unpark_fields);
        let m1_bits = merge_sp_m1.map_or(0, |_| spw);
        let unpark = fifo(b, "unpark_q", sb + spw + 1 + m1_bits, k, inp.merge_valid, unpark_in, unpark_pop);
        // The head without sp − 1 (the entry the fields below are cut from), and sp − 1.
        let (unpark_head, unpark_sp_m1) = match merge_sp_m1 {
            Some(_) => (unpark.head.slice(m1_bits, sb + spw + 1), Some(unpark.head.slice(0, spw))),
            None => (unpark.head, None),
        };
        let new_in = b.cat(&[inp.new_slot, inp.new_tmax.unsigned(), inp.new_miss]);
        let newq = fifo(b, "new_q", sb + dist.width + 1, k, inp.new_valid, new_in, new_pop);
        // E: a queued ray enters when the token now in G will not return (R empty in A); a node
        // step back from the retry queue first (its ray is walking), once its line is in.
        let retry = inp.cache.map(|c| self.retry_queue(c));
        let free = || match retry {
            Some(r) => !ring_g_valid & !r.ready,
            None => !ring_g_valid,
        };
        let take_unpark = (free() & unpark.nonempty).name("take_unpark");
        let take_new = (free() & !unpark.nonempty & newq.nonempty).name("take_new");
        b.drive(unpark_pop, take_unpark);
        b.drive(new_pop, take_new);
        let retried = retry.map(|r| {
            let take = (!ring_g_valid & r.ready).name("take_retry");
            b.drive(r.pop, take);
            (take, r)
        });
        let taken = match retried {
            Some((take, _)) => take | take_unpark | take_new,
            None => take_unpark | take_new,
        };
        let valid = b.valid_delay("q_valid", taken);
        let new = b.delay("q_new", take_new);
        // A retried step's fields, else `queued`.
        let or_retried = |field: fn(&RetryQueue<'b>) -> S<'b>, queued: S<'b>| match &retried {
            Some((take, r)) => take.select(field(r), queued),
            None => queued,
        };
        let queued_slot = take_unpark.select(unpark_head.slice(spw + 1, sb), newq.head.slice(dist.width + 1, sb));
        let slot_next = or_retried(|r| r.slot, queued_slot);
        let slot = b.delay("q_slot", slot_next);
        // An unparked ray's stack pointer, with sp = 0 and sp − 1 made here, so that A is muxes.
        let head_sp = or_retried(|r| r.sp, unpark_head.slice(1, spw));
        let sp = b.delay("q_sp", head_sp);
        let sp_zero = b.delay("q_sp_zero", head_sp.eq(0));
        let sp_m1_next = match unpark_sp_m1 {
            Some(m1) => or_retried(|r| r.sp - 1, m1),
            None => head_sp - 1,
        };
        let sp_m1 = b.delay("q_sp_m1", sp_m1_next);
        let raddr_next = b.cat(&[slot_next, sp_m1_next.resize(self.stack_bits)]).name("q_stack_raddr");
        // Whether the token taken is done in A, decided here: from `q_new`, `q_miss` and the
        // stack pointer's bits in A, the done and live bits were the slowest paths of a
        // traversal unit at seed 2 of the default core (8.29 ns into `b_valid`).
        let unpark_empty = unpark_head.bit(0);
        let done_c = ((take_new & newq.head.bit(0)) | (take_unpark & unpark_empty)).name("q_done_c");
        let done = b.delay("q_done", done_c);
        let tmax = b.delay("q_tmax", or_retried(|r| r.tmax, newq.head.slice(1, dist.width).signed()));
        let retry = retried.map(|(take, r)| Retried {
            valid: b.delay("q_retry", take),
            node: b.delay("q_node", r.node),
            tmin: b.delay("q_tmin", r.tmin),
            push: r.push,
            entry: r.entry,
        });
        Queued { ring_g_valid, valid, new, slot, sp, sp_zero, sp_m1, tmax, done, raddr_next, retry }
    }
}
