//! The BIH traversal unit with ray slots (seed 001 §3.4 made multithreaded, issue 12): it holds
//! K rays at once, each in a slot with its own stack, and steps one node per clock for any of
//! them, so its pipelined plane-distance and decision stages are filled by different rays. The
//! walk of each ray is `Golden::trace_culled`'s, in its order: near child first, far child
//! pushed, a node entry skipped when lower_t(tmin) > the best t found so far.
//!
//! A ray is a **token** going round a ring of registers, one stage per clock (offsets from A;
//! C = 3, N = C + node ROM clocks, F = N + L, L the plane unit's latency):
//! - A: the token is the ring's returning one (R) or, when R is empty, one from the queues
//!   (rays unparked after a leaf, new rays); a pop reads the slot's stack at sp − 1, a pop of
//!   an empty stack or a ray that misses the scene box is **done** (its slot number goes to
//!   the done queue) and leaves the ring.
//! - B, B2: the stack is a block RAM read in two clocks (its output register); in B2 a popped
//!   token takes (node, tmin, tmax) from the stack word.
//! - C: the node ROM is addressed; the cull test's operands are read (the slot's best t + 8
//!   from the limit RAM, whether it has a best hit; tmin − tmin/64).
//! - N: the node word. A culled entry or an empty leaf goes on as a pop. A leaf with entries is
//!   queued for the leaf stream (slot, first, count, tmin, sp) and the token leaves the ring: the
//!   slot is **parked** until the closest-hit unit has merged the leaf's results into the slot's
//!   best hit and sends it back (`merge_*`), so every cull sees the hits of every leaf before it,
//!   as the golden walk's does. An inner node issues both plane distances, one to each of two
//!   plane units; the slot's origin and reciprocal direction are read from the ray RAMs for them.
//! - F: both distances arrive and are compared, by their roles, with limits made from tmin and
//!   tmax on the way (`bih::inner_step`'s decision, as compares only).
//! - G: the decision: push the far child (stack[slot][sp]) and enter the near one, enter one
//!   child, or pop. The token goes into R and is back at A in the next cycle.
//!
//! - F2 (only in a unit that sends leaves, `pair_rom_cycles`): F's compares registered; the
//!   leaf to send, and so whether the token returns, is decided from them.
//!
//! Ring length P = N + L + 2 clocks (18 at the default 150 MHz with block ROMs; one more with
//! F2): a slot steps once per P clocks, so K ≥ P slots keep the ring full when no slot is
//! parked.
//!
//! Slots: a free list (`free_list.rs`: slots unused since reset in order, then slots given back
//! in the order they came back); the top takes the slot offered (`alloc`) and writes the
//! ray's origin and reciprocal direction into the ray RAMs, and later the ray's scene-box exit
//! distance comes in through the new-ray queue (`new_*`). A slot is freed by the top when the
//! ray's result has left the core (`free_*`), so a slot's best hit is never read after reuse.

use super::fifo::{Fifo, fifo};
use super::free_list::FreeList;
use super::traverse_stages::{RingN, Unit};
use crate::rtl::Module;
use crate::rtl::build::Builder;
use crate::rtl::build::S;

pub use super::traverse_params::{TraverseParams, field, pair_image, word_bits};

/// The unit. Inputs: the ray RAM write (`ray_we_gI`, `ray_slot_gI` for each group I of the
/// RAMs' LUT-RAM columns, `TraverseParams::ray_ram_groups`; ox, oy, oz, invx, invy, invz),
/// a new ray's box exit (`new_valid`, `new_slot`, `new_tmax`, `new_miss`), a leaf merged
/// (`merge_valid`, `merge_slot`, `merge_hit`, `merge_limit` = best t + 8, `merge_sp`), a slot
/// freed (`free_valid`, `free_slot`), `alloc` (the top takes `free_slot_out`), `leaf_pop` and
/// `done_pop` (the heads of the leaf and done queues are taken; the pop takes effect a clock
/// later, so the head is not taken again in the next clock), `node_word` (the node ROM's
/// word at `node_addr`, `node_rom_cycles` after it). Outputs: `node_addr`, the slot offered
/// (`has_free`, `free_slot_out`), the leaf queue's head (`leaf_valid`, `leaf_slot`, `leaf_first`,
/// `leaf_count`, `leaf_tmin`, `leaf_sp`), the done queue's head (`done_valid`, `done_slot`), and
/// observations: `visit` (a node visited in N, `visit_slot`, `visit_node`), `cull`, `depth`
/// (the stack depth in N), `occupied` (slots holding a ray).
pub fn traverse_core(p: &TraverseParams) -> Module {
    assert!((1..=64).contains(&p.slots), "1 to 64 slots per unit");
    let b = Builder::new(&format!("fxrt_traverse_k{}_{}", p.slots, p.scene_tag));
    let u = Unit::new(&b, p);
    let slots = u.slots();
    let q = u.queues();
    let r = u.returning();
    let a = u.ring_a(&r, &q);
    let (bt, b_from_stack) = u.ring_b(&a, &r, &q);
    b.stage("done", "the done queue: slots whose ray left the ring in A, for the top");
    // The top's pops arrive a clock late (registered here: the top's arbiter sits across the
    // die), so it does not take from a queue again in the clock after it took.
    let done = fifo(&b, "done_q", u.sb, p.slots, a.done, a.slot, b.valid_delay("done_pop_r", u.inp.done_pop));
    let (c, [culled_first, culled], lookup) = u.ring_c(bt, b_from_stack, a.stack_top, &q);
    let n = u.ring_n(c, culled, &q);
    let f = u.ring_f(&n);
    let sent = u.ring_g(&f, &r, &a, &q);
    b.end_stage();
    let leafq = match (n.leafq.as_ref(), sent.as_ref()) {
        (Some(leafq), None) => leafq,
        (None, Some((leafq, [valid, slot, node]))) => {
            b.output("sent", *valid);
            b.output("sent_slot", *slot);
            b.output("sent_node", *node);
            leafq
        }
        _ => unreachable!("one leaf queue, in N or in G"),
    };
    match lookup {
        // With a node cache: the lookup a clock after C.
        Some([valid, node]) => {
            b.output("node_look", valid);
            b.output("node_look_culled", culled_first);
            u.outputs(&slots, node, &n, leafq, &done);
        }
        None => u.outputs(&slots, c.node, &n, leafq, &done),
    }
    b.finish()
}

impl<'b> Unit<'b> {
    /// The output ports (see `traverse_core`).
    pub(super) fn outputs(
        &self,
        slots: &FreeList<'b>,
        node_addr: S<'b>,
        nn: &RingN<'b>,
        leafq: &Fifo<'b>,
        done: &Fifo<'b>,
    ) {
        let (b, p, nt) = (self.b, self.p, nn.token);
        b.output("node_addr", node_addr);
        b.output("has_free", (slots.free_any & !slots.just_alloc).name("has_free_c"));
        b.output("free_slot_out", slots.free_idx);
        let lh = leafq.head;
        let mut at = 0;
        let mut take = |w: u32| {
            let s = lh.slice(at, w);
            at += w;
            s
        };
        let count_w = p.node_layout.field("count").width;
        let leaf_bits = self.leaf_bits;
        let (l_sp, l_tmin, l_count, l_first, l_slot) =
            (take(self.spw), take(p.tmin_width()), take(count_w), take(leaf_bits), take(self.sb));
        b.output("leaf_valid", leafq.nonempty);
        b.output("leaf_slot", l_slot);
        b.output("leaf_first", l_first);
        b.output("leaf_count", l_count);
        b.output("leaf_tmin", l_tmin);
        b.output("leaf_sp", l_sp);
        b.output("done_valid", done.nonempty);
        b.output("done_slot", done.head);
        b.output("visit", nn.visit);
        b.output("visit_slot", nt.slot);
        b.output("visit_node", nt.node);
        b.output("cull", (nt.valid & nn.culled).name("cull_c"));
        b.output("depth", nt.sp);
        b.output("occupied", slots.occupied);
    }
}
