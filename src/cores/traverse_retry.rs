//! The traversal unit's node cache side (an external-memory core, docs/MEMORY.md "The
//! traversal with a node cache"): the lookup one clock after C, and the **retry queue** of node
//! steps that missed. A miss in N takes the token out of the ring with everything it needs to
//! step again — slot, node, tmin, tmax, sp — and the number of the fill that brings its line;
//! the queue's head goes back into the ring at A (before rays back from a leaf and new rays)
//! once the cache's `done` counter has reached that number. The walk is unchanged: a step that
//! missed is neither a visit nor a cull, and when it comes back its cull test sees the same best
//! hit (the slot's best changes only when a leaf it sent is merged, and the slot sends nothing
//! while it waits here). The queue holds one entry per slot at most, so it never overflows.
//!
//! The retry queue is in order: a head waiting for a later fill holds back an entry whose fill
//! came earlier. That costs a few clocks, never a deadlock: fills come whatever the ring does.

use super::cache::{SEQ_BITS, ready_when_released};
use super::fifo::{fifo, unpack};
use super::traverse_stages::{NodeAnswer, RetryQueue, Token, Unit};
use crate::rtl::Ty;
use crate::rtl::build::S;

impl<'b> Unit<'b> {
    /// Entry bits, most significant first: slot, node, tmin, tmax, sp, the fill to wait for.
    fn retry_widths(&self) -> [u32; 6] {
        let d = self.dist.width;
        [self.sb, self.node_bits, d, d, self.spw, SEQ_BITS]
    }

    pub(super) fn retry_queue(&self, cache: NodeAnswer<'b>) -> RetryQueue<'b> {
        let b = self.b;
        let widths = self.retry_widths();
        let width = widths.iter().sum();
        let push = b.wire("retry_push", Ty::BIT);
        let entry = b.wire("retry_entry", Ty::u(width));
        let pop = b.wire("retry_pop", Ty::BIT);
        let q = fifo(b, "retry_q", width, self.p.slots, push, entry, pop);
        let [slot, node, tmin, tmax, sp, wait] = unpack(q.head, &widths)[..] else { unreachable!("six fields") };
        // Registered, so A's choice (a retry before rays back from a leaf and new rays) starts at
        // a register (the subtract, A's pops and the unpark queue's count were 16.6 ns).
        let ready = ready_when_released(b, "retry", q.nonempty, cache.done, wait, pop);
        RetryQueue { ready, pop, slot, node, tmin: tmin.signed(), tmax: tmax.signed(), sp, push, entry }
    }

    /// N with a node cache: a step that is not culled and misses leaves the ring for the retry
    /// queue (`retry`: its push port). Returns the miss.
    pub(super) fn retry_push(
        &self,
        t: Token<'b>,
        culled: S<'b>,
        cache: NodeAnswer<'b>,
        push: S<'b>,
        entry: S<'b>,
    ) -> S<'b> {
        let b = self.b;
        let miss = (t.valid & !culled & !cache.hit).name("node_miss");
        b.drive(push, miss);
        b.drive(entry, b.cat(&[t.slot, t.node, t.tmin.unsigned(), t.tmax.unsigned(), t.sp, cache.wait]));
        miss
    }
}
