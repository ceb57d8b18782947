//! The BIH traversal unit (seed 001 §3.4, figure 3.6, table 3.1): a state machine that takes
//! one ray at a time and emits, one per clock, every triangle of every leaf the ray visits,
//! in exactly the order of `Golden::walk` (near child first, far child pushed, no early out).
//! The node and leaf ROMs and the stack RAM are synchronous block memories.
//!
//! Pipelined for the clock: every register-to-register path is a block-RAM read into a
//! register, one mux level and one adder or compare (or a few LUTs of decision), or the
//! multiplier alone. So the node ROM is addressed by the `node` register itself and its word
//! goes straight into registers (a block ROM, `brom.rs`: mem[node] two or three cycles after
//! `node` last changed), as does the leaf ROM's; the plane distances come from a pipelined
//! unit (`plane.rs`, L = 3 + product stages clocks from issue to result, + 1 with a split
//! product; L = 10 at the default 150 MHz); and the child decision takes a compare cycle and an act cycle. States and their
//! cost (one cycle each unless noted):
//! - `idle`: `ray_ready`; a valid ray is latched (node 0 and tmin 0 too).
//! - `aabb` (3 cycles): the exit distance of one scene-box axis per cycle is issued.
//! - `box` (L cycles): waits for the three distances, registering them and their compares.
//! - `boxmin`: tmax = their min. A ray that misses the box (a distance < 0) goes to `done`,
//!   else to `node` (node 0's word was read while waiting).
//! - `fetch`: waits until the word register holds the new node's word: 2 cycles after a step
//!   that enters the far child alone, 1 after a pop that follows a step or a one-entry leaf, 2
//!   after a pop that follows an empty leaf. The near child is addressed during `dist`
//!   and the stack top during `leaf`, so descending near and popping after a leaf of two or
//!   more entries need none.
//! - `node` (1 per node visit): the node word is in its register. A leaf loads its first entry
//!   and count; an inner node's fields are latched and d0 (clip0) is issued.
//! - `clip1` (1 per inner node): d1 (clip1) is issued; the ray's sign on the axis latched.
//! - `dist` (L per inner node): waits for d0, then d1. Each is compared, the cycle it arrives,
//!   with the limits of its role (near_end or far_start, known from the sign); when d1
//!   arrives, near_end/far_start are chosen and the decision bits registered.
//! - `step` (1 per inner node): `bih::inner_step`'s decision from the registered compares,
//!   selected by the ray's sign: push the far child and enter the near one, enter one child,
//!   or pop.
//! - `leaf` (count cycles): one leaf entry per clock.
//! - `pop`: the top of the stack (always read ahead) is loaded, or `done` when it is empty.
//! - `done`: an end token follows the ray's last triangle, so the closest-hit unit knows the
//!   ray is complete when the token leaves the in-order pipeline.
//!
//! An inner node costs node + clip1 + L + step = 3 + L cycles (13 by default; 2 before the
//! unit was pipelined; a far-only step adds the node ROM's 2 or 3 read clocks of `fetch`), a
//! leaf node + count, a pop 1 (+ its fetch), a ray's overhead idle + aabb + box + boxmin +
//! done = 6 + L. Emission is the leaf ROM's 2 or 3 read clocks behind `leaf`.

use super::brom::{brom, read_cycles};
use super::clock::ClockTarget;
use super::lt_chain;
use super::mul::MulStyle;
use super::plane::{PlaneIssue, plane_unit};
use crate::rtl::build::{Builder, S};
use crate::rtl::fsm::Fsm;
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use crate::scene::rom::{self, Field, Word, rom_addr_bits};

crate::states! {
    /// The traversal unit's states, in encoding order.
    pub enum TravState {
        Idle = "idle",
        Aabb = "aabb",
        Box = "box",
        BoxMin = "boxmin",
        Fetch = "fetch",
        Node = "node",
        Clip1 = "clip1",
        Dist = "dist",
        Step = "step",
        Leaf = "leaf",
        Pop = "pop",
        Done = "done",
    }
}

/// The widths of one traversal unit.
#[derive(Clone, Debug)]
pub struct TraverseParams {
    pub n: u32,
    pub m: u32,
    pub c: u32,
    pub id_width: u32,
    pub stack_depth: u32,
    pub box_hi: [i64; 3],
    pub tri_bits: u32,
    /// How the plane-distance product is built (`plane::plane_product`): the clock target's.
    pub product: MulStyle,
    /// Clocks of a node ROM read and of a leaf ROM read (`brom::read_cycles`: 3 for block RAM,
    /// whose fabric register the placer puts between the blocks spread over the die and the
    /// logic; 2 for LUTs). The emitted triangle stream is `leaf_rom_cycles` behind `leaf`.
    pub node_rom_cycles: u32,
    pub leaf_rom_cycles: u32,
}

impl TraverseParams {
    pub fn new(scene: &SceneRoms, id_width: u32, target: ClockTarget) -> TraverseParams {
        let p = &scene.params;
        TraverseParams {
            n: p.n,
            m: p.m,
            c: p.c,
            id_width,
            stack_depth: p.stack_depth,
            box_hi: scene.box_hi,
            tri_bits: rom::addr_bits(scene.tri_count()),
            product: target.mul_style(),
            node_rom_cycles: read_cycles(scene.node.1.len()),
            leaf_rom_cycles: read_cycles(scene.leaf.1.len()),
        }
    }
    /// Reciprocal directions: m + C bits.
    pub fn inv_width(&self) -> u32 {
        self.m + self.c
    }
    /// Distances: −1 … 2^(n+1), signed n + 3 bits.
    pub fn dist_ty(&self) -> Ty {
        Ty::s(self.n + 3)
    }
    /// Leaf entry distances are never negative: unsigned n + 2 bits.
    pub fn tmin_width(&self) -> u32 {
        self.n + 2
    }
    pub fn sp_width(&self) -> u32 {
        rom::value_bits(self.stack_depth as usize)
    }
}

/// Bits [lsb, lsb + width) of a ROM word (width ≤ 128).
pub fn word_bits(w: &Word, lsb: u32, width: u32) -> u128 {
    (0..width).fold(0u128, |acc, b| {
        let bit = lsb + b;
        acc | ((((w.0[(bit / 64) as usize] >> (bit % 64)) & 1) as u128) << b)
    })
}

/// A field of a ROM read: its bits as a signal of the field's type.
pub fn field<'b>(name: &str, word: S<'b>, f: &Field, word_lsb: u32) -> S<'b> {
    let raw = word.slice(f.lsb - word_lsb, f.width);
    if f.signed { raw.signed().name(name) } else { raw.name(name) }
}

/// Ports of the unit, in order: inputs, then outputs.
pub fn traverse_core(p: &TraverseParams, scene: &SceneRoms) -> Module {
    use TravState::*;
    let ((node_l, node_words), (leaf_l, leaf_words)) = (&scene.node, &scene.leaf);
    let b = Builder::new("fxrt_traverse");
    let (n, dist) = (p.n, p.dist_ty());
    let ray_valid = b.input("ray_valid", Ty::BIT);
    let ray_id = b.input("ray_id", Ty::u(p.id_width));
    let o_in = ["ox", "oy", "oz"].map(|s| b.input(s, Ty::u(n)));
    let inv_in = ["invx", "invy", "invz"].map(|s| b.input(s, Ty::s(p.inv_width())));
    let fsm = Fsm::new(&b, "state", "BIH traversal: one ray at a time, one leaf entry per clock", Idle);

    // The ray, latched when it is accepted.
    let id_r = b.reg("ray_id_r", ray_id.ty(), None);
    let o = ["ox_r", "oy_r", "oz_r"].map(|name| b.reg(name, Ty::u(n), None));
    let inv = ["invx_r", "invy_r", "invz_r"].map(|name| b.reg(name, Ty::s(p.inv_width()), None));

    // Node ROM, addressed by the node register itself, its word registered before any logic
    // sees it (a block RAM's clock-to-out leaves no room for logic in the same clock): a block
    // ROM (`brom.rs`) of `node_rom_cycles` clocks, whose word holds mem[node] when node has
    // held its value for the `node_rom_cycles` cycles before. `node_settled` (node unchanged
    // over the last node_rom_cycles − 1 cycles) tells `fetch` the word will be there in the
    // next cycle.
    let node_bits = rom_addr_bits(node_words.len());
    let node = b.reg("node", Ty::u(node_bits), Some(0));
    let node_image = node_words.iter().map(|w| word_bits(w, 0, node_l.width)).collect();
    let word = brom(&b, "u_node_rom", "node", node_l.width, node_image, node, p.node_rom_cycles);
    let node_settled = (1..p.node_rom_cycles)
        .map(|k| node.eq(b.delay_line(&format!("node_d{k}"), node, k)))
        .reduce(|a, c| a & c)
        .expect("a ROM of two clocks or more")
        .name("node_settled");
    let nf = |name: &str| field(&format!("nw_{name}"), word, node_l.field(name), 0);
    let (w_axis, w_clip0, w_clip1, w_child, w_first, w_count) =
        (nf("axis"), nf("clip0"), nf("clip1"), nf("child"), nf("first"), nf("count"));
    let w_leaf = w_axis.eq(3).name("nw_is_leaf");

    // The inner node's fields and the ray interval.
    let axis_r = b.reg("axis_r", Ty::u(2), None);
    let clip1_r = b.reg("clip1_r", Ty::u(n), None);
    let child_r = b.reg("child_r", w_child.ty(), None);
    let aabb_k = b.reg("aabb_k", Ty::u(2), None);
    let tmin = b.reg("tmin", dist, None);
    let tmax = b.reg("tmax", dist, None);

    // The plane-distance unit. The select puts the node word's fields last, so they pass one
    // mux level between the word register and the unit's first register.
    let (in_aabb, in_node, in_clip1) = (fsm.is(Aabb), fsm.is(Node), fsm.is(Clip1));
    let hi = [0, 1, 2].map(|k| b.konst_named(&format!("box_hi_{k}"), Ty::u(n), p.box_hi[k] as i128));
    let aabb_neg = b.pick(aabb_k, inv).msb().name("aabb_neg");
    let aabb_plane = aabb_neg.select(hi[0].k(0), b.pick(aabb_k, hi)).name("aabb_plane");
    let aabb_last = aabb_k.eq(2).name("aabb_last");
    let issue = PlaneIssue {
        valid: (in_aabb | in_clip1 | (in_node & !w_leaf)).name("pu_issue"),
        last: (in_clip1 | (in_aabb & aabb_last)).name("pu_issue_last"),
        plane: in_node.select(w_clip0, in_aabb.select(aabb_plane, clip1_r)).name("pu_issue_plane"),
        axis: in_node.select(w_axis, in_aabb.select(aabb_k, axis_r)).name("pu_issue_axis"),
    };
    let pu = plane_unit(&b, n, p.c, o, inv, issue, p.product);
    let (plane_t, d1_arrives) = (pu.t, (pu.valid & pu.last).name("d1_arrives"));

    // box and boxmin: tmax = the least of the three exit distances (each at most the clamp's
    // ceiling 2^(n+1), where the walk starts tmax); the box is missed when one of them is
    // negative. The three arrive in consecutive cycles; the last two and the one before are
    // in `box_d1`..`box_d3` in the cycle after (`boxmin`), and so are their compares, each a
    // carry chain into a flip-flop (a running min would be a compare, a select and the state
    // machine's mux in one cycle, 9.4 ns). All of these load every cycle.
    let box_d1 = b.delay("box_d1", plane_t);
    let box_d2 = b.delay("box_d2", box_d1);
    let box_d3 = b.delay("box_d3", box_d2);
    let box_lt1 = b.delay("box_lt1", lt_chain(plane_t, box_d1).name("box_lt1_c"));
    let box_lt2 = b.delay("box_lt2", lt_chain(plane_t, box_d2).name("box_lt2_c"));
    let box_lt1_d = b.delay("box_lt1_d", box_lt1);
    // In boxmin: c = box_d1, b = box_d2, a = box_d3; c < b is box_lt1, c < a box_lt2, b < a
    // box_lt1_d.
    let box_tmax = (box_lt1 & box_lt2).select(box_d1, box_lt1_d.select(box_d2, box_d3)).name("box_tmax");
    let box_miss = (box_d1.msb() | box_d2.msb() | box_d3.msb()).name("box_miss");

    // dist: bih::inner_step's compares. tmin ≤ min(near_end, tmax) and max(tmin, far_start) ≤
    // tmax are each a compare with one distance and tmin ≤ tmax, so no min or max feeds a
    // compare; every compare is a strict less-than (x ≤ tmax is x < tmax + 1, tmin ≤ x is
    // tmin − 1 < x). The ray's sign on the axis (`negative`, set in `clip1`) is known long
    // before d0 arrives, so each distance's role is too: d0 is near_end when the sign is
    // positive, far_start when negative, and d1 the other. So each distance is compared only
    // with the limits of its role, two compares each instead of four, and the limits
    // (`d0_hi` … `d1_lo`) are registers of their own chosen by the sign ahead of time, with
    // tmin ≤ tmax folded in: when tmin > tmax every limit is one no distance passes (the most
    // negative value as an upper limit, the most positive as a lower; distances lie in
    // [−1, 2^(n+1)], limits in [−1, 2^(n+1) + 1], and the type holds ±2^(n+2)), so both
    // decisions fail and the step pops, as `inner_step` does. The limits load every cycle; tmin
    // and tmax hold still from `node` to `step`, so the limits are current 3 cycles after
    // `node` (tmax → tmax + 1 → tmin ≤ tmax → limit), before d0 arrives (L ≥ 4 cycles).
    // They also spare tmin and tmax the fan-out to the compares (yosys keeps them apart: they
    // are other functions).
    //
    // d0 is compared from the plane unit's copy that holds a group's first distance, the cycle
    // it arrives, into registers; d1 the cycle after, from the copy of the last. Each decision
    // register then loads, every cycle, d1's compare or d0's registered one, by the sign: a
    // carry chain and one LUT, and the state machine reads flip-flops (with the sign select in
    // `step`, the state logic ran through the compares' corner of the die and back: 8.4 ns in
    // the whole teapot core). Every compare is `lt_chain`: the sign of a difference one bit
    // wider, the chain's last sum bit, no carry-out and no LUT after the chain.
    assert!(pu.latency >= 4, "the decision limits need 3 cycles after node");
    let negative = b.reg("negative", Ty::BIT, None);
    let (d0, d1) = (pu.t_first, pu.t_last);
    let near_end = negative.select(d1, d0).name("near_end");
    let far_start = negative.select(d0, d1).name("far_start");
    let tmax_p1 = b.delay("tmax_p1", (tmax + 1).name("tmax_plus_1"));
    let tmin_m1 = b.delay("tmin_m1", (tmin - 1).name("tmin_minus_1"));
    let tmin_le_tmax = b.delay("tmin_le_tmax", lt_chain(tmin, tmax_p1).name("tmin_le_tmax_c"));
    let never_below = tmax.k(-(1i128 << (n + 2)));
    let never_above = tmax.k((1i128 << (n + 2)) - 1);
    let limit = |name: &str, if_negative: S, if_positive: S, never: S| {
        let l = tmin_le_tmax.select(negative.select(if_negative, if_positive), never);
        b.delay(name, l.name(&format!("{name}_c")))
    };
    // x < hi: near_end < tmax (near_lt_tmax) or far_start < tmax + 1 (far_le_tmax); lo < x:
    // tmin − 1 < near_end (tmin_le_near) or tmin < far_start (far_gt_tmin).
    let d0_hi = limit("d0_hi", tmax_p1, tmax, never_below);
    let d0_lo = limit("d0_lo", tmin, tmin_m1, never_above);
    let d1_hi = limit("d1_hi", tmax, tmax_p1, never_below);
    let d1_lo = limit("d1_lo", tmin_m1, tmin, never_above);
    let d0_below = b.delay("d0_below", lt_chain(d0, d0_hi).name("d0_below_c"));
    let d0_above = b.delay("d0_above", lt_chain(d0_lo, d0).name("d0_above_c"));
    let d1_below = lt_chain(d1, d1_hi).name("d1_below");
    let d1_above = lt_chain(d1_lo, d1).name("d1_above");
    // Registered the cycle d1 arrives, read in `step`: (negative: from d1, positive: from d0).
    let reg = |name: &str, if_negative: S, if_positive: S| {
        b.delay(name, negative.select(if_negative, if_positive).name(&format!("{name}_c")))
    };
    let near_lt_tmax = reg("near_lt_tmax", d1_below, d0_below);
    let far_gt_tmin = reg("far_gt_tmin", d0_above, d1_above);
    let go_near = reg("go_near", d1_above, d0_above);
    let go_far = reg("go_far", d0_below, d1_below);
    let near_end_r = b.reg("near_end_r", dist, None);
    let far_start_r = b.reg("far_start_r", dist, None);
    let far_r = b.reg("far_r", Ty::u(node_bits), None);
    let child_b = child_r + 1;
    let near = negative.select(child_b, child_r).resize(node_bits).name("near");
    let far = negative.select(child_r, child_b).resize(node_bits).name("far");

    // step: the decision from registered bits; near_max and far_min are muxes.
    let near_max = near_lt_tmax.select(near_end_r, tmax).name("near_max");
    let far_min = far_gt_tmin.select(far_start_r, tmin).name("far_min");

    // Stack entries (far node, far_min, tmax); the top (sp − 1) is always read ahead.
    let sp = b.reg("sp", Ty::u(p.sp_width()), Some(0));
    let stack_bits = rom_addr_bits(p.stack_depth as usize);
    let stack = b.ram("stack", node_bits + 2 * dist.width, vec![0; p.stack_depth as usize]);
    let entry = b.cat(&[far_r, far_min.unsigned(), tmax.unsigned()]).name("push_entry");
    // The read address sp − 1 in a register of its own, set wherever sp is (to the new sp − 1):
    // an adder between sp and the LUT RAM's read address, spread over the die, made the
    // whole Cornell core's critical path (7.3 ns, 5.4 ns of it routing).
    let top_addr = b.reg("stack_top_addr", Ty::u(stack_bits), Some((1i128 << stack_bits) - 1));
    let top = b.read("stack_top", stack, top_addr);
    let top_tmax = top.slice(0, dist.width).signed().name("top_tmax");
    let top_tmin = top.slice(dist.width, dist.width).signed().name("top_tmin");
    let top_node = top.slice(2 * dist.width, node_bits).name("top_node");

    // Leaf entries, one per clock.
    let leaf_bits = rom_addr_bits(leaf_words.len());
    let leaf_ptr = b.reg("leaf_ptr", Ty::u(leaf_bits), None);
    let left = b.reg("leaf_left", w_count.ty(), None);
    // Whether `node` has held the stack top since `node_rom_cycles` cycles before `node`
    // follows `pop` (so the word is there without a `fetch`): `leaf` loads the top every
    // cycle, so a leaf of `node_rom_cycles` or more entries has. The top is read at sp − 1 one
    // cycle late, so it is current in `leaf` and `step`, not in a `node` right after a push.
    let popped_ahead = b.reg("popped_ahead", Ty::BIT, None);
    let was_leaf = (1..p.node_rom_cycles)
        .map(|k| b.delay_line(&format!("was_leaf{k}"), fsm.is(Leaf), k))
        .reduce(|a, c| a & c)
        .expect("a ROM of two clocks or more")
        .name("was_leaf");
    // Whether the stack is empty, registered: `pop` never follows a cycle that changed sp.
    let sp_empty = b.delay("sp_empty", sp.eq(0).name("sp_is_zero"));

    fsm.state(Idle, |s| {
        s.set_k(aabb_k, 0);
        s.set_k(node, 0);
        s.set_k(tmin, 0);
        s.when(ray_valid, |s| {
            s.set(id_r, ray_id);
            for k in 0..3 {
                s.set(o[k], o_in[k]);
                s.set(inv[k], inv_in[k]);
            }
            s.goto(Aabb);
        });
    });
    fsm.state(Aabb, |s| {
        s.set(aabb_k, aabb_k + 1);
        s.when(aabb_last, |s| s.goto(Box));
    });
    fsm.state(Box, |s| {
        s.when(d1_arrives, |s| s.goto(BoxMin));
    });
    fsm.state(BoxMin, |s| {
        s.set(tmax, box_tmax);
        s.when(box_miss, |s| s.goto(Done)).otherwise(|s| s.goto(Node));
    });
    fsm.state(Fetch, |s| {
        s.when(node_settled, |s| s.goto(Node));
    });
    fsm.state(Node, |s| {
        s.when(w_leaf, |s| {
            s.set(leaf_ptr, w_first.resize(leaf_bits));
            s.set(left, w_count);
            s.set_k(popped_ahead, 0);
            s.when(w_count.eq(0), |s| s.goto(Pop)).otherwise(|s| s.goto(Leaf));
        })
        .otherwise(|s| {
            // d0 is issued this cycle (the unit's select reads the word).
            s.set(axis_r, w_axis);
            s.set(clip1_r, w_clip1);
            s.set(child_r, w_child);
            s.goto(Clip1);
        });
    });
    fsm.state(Clip1, |s| {
        // d1 is issued this cycle.
        s.set(negative, b.pick(axis_r, inv).msb());
        s.goto(Dist);
    });
    fsm.state(Dist, |s| {
        // The near child is the likely next node: addressing the ROM with it now has its word
        // ready when `step` enters it, so only a far-only step pays a `fetch`.
        s.set(node, near);
        s.set(far_r, far);
        s.when(d1_arrives, |s| {
            // The compares are registered every cycle: in `step` they hold this cycle's.
            s.set(near_end_r, near_end);
            s.set(far_start_r, far_start);
            s.goto(Step);
        });
    });
    fsm.state(Step, |s| {
        s.when(go_near & go_far, |s| {
            s.write(stack, sp.resize(stack_bits), entry);
            s.set(sp, sp + 1);
            s.set(top_addr, sp.resize(stack_bits));
        });
        s.when(go_near, |s| {
            s.set(tmax, near_max);
            s.goto(Node);
        })
        .otherwise(|s| {
            s.when(go_far, |s| {
                s.set(tmin, far_min);
                s.set(node, far_r);
                s.goto(Fetch);
            })
            .otherwise(|s| {
                s.set(node, top_node);
                s.set_k(popped_ahead, 0);
                s.goto(Pop);
            });
        });
    });
    fsm.state(Leaf, |s| {
        s.set(leaf_ptr, leaf_ptr + 1);
        s.set(left, left - 1);
        s.set(node, top_node);
        s.when(left.eq(1), |s| {
            s.set(popped_ahead, was_leaf);
            s.goto(Pop);
        });
    });
    fsm.state(Pop, |s| {
        s.when(sp_empty, |s| s.goto(Done)).otherwise(|s| {
            s.set(sp, sp - 1);
            s.set(top_addr, (sp - 2).resize(stack_bits));
            s.set(tmin, top_tmin);
            s.set(tmax, top_tmax);
            s.set(node, top_node);
            s.when(popped_ahead, |s| s.goto(Node)).otherwise(|s| s.goto(Fetch));
        });
    });
    fsm.state(Done, |s| s.goto(Idle));
    let (in_idle, in_leaf, in_done) = (fsm.is(Idle), fsm.is(Leaf), fsm.is(Done));
    let state = fsm.state_reg();
    fsm.finish();

    // Emission, `leaf_rom_cycles` behind the FSM so it lines up with the leaf ROM's word (a block
    // ROM), which addresses the triangle ROMs.
    let leaf_image = leaf_words.iter().map(|w| word_bits(w, 0, leaf_l.width)).collect();
    let tri = brom(&b, "u_leaf_rom", "leaf", leaf_l.width, leaf_image, leaf_ptr, p.leaf_rom_cycles);
    b.output("ray_ready", in_idle);
    b.output("emit_valid", b.delay_line("emit_r", in_leaf | in_done, p.leaf_rom_cycles));
    b.output("emit_end", b.delay_line("end_r", in_done, p.leaf_rom_cycles));
    b.output("emit_tri", tri.resize(p.tri_bits));
    b.output("emit_tmin", b.delay_line("tmin_r", tmin.unsigned().resize(p.tmin_width()), p.leaf_rom_cycles));
    b.output("emit_id", b.delay_line("id_r", id_r, p.leaf_rom_cycles));
    for (name, s) in ["cur_ox", "cur_oy", "cur_oz"].iter().zip(o) {
        b.output(name, s);
    }
    // Observation ports: a node visit (for the order check and statistics) and the stack depth.
    b.output("visit", in_node);
    b.output("visit_node", node);
    b.output("stack_depth", sp);
    b.output("fsm_state", state);
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::camera::Camera;
    use crate::model::golden::{Golden, GridRay, Visitor};
    use crate::model::ray::quantize_ray;
    use crate::params::Params;
    use crate::rtl::sim::Sim;
    use crate::scene::images::SceneRoms;
    use crate::scene::{Scene, SceneSource};

    /// What a traversal did: node visits and (triangle, leaf tmin) emissions, in order.
    #[derive(Debug, Default, PartialEq, Eq)]
    struct Trace {
        nodes: Vec<u32>,
        tris: Vec<(u32, i64)>,
        max_stack: u32,
    }

    impl Visitor for Trace {
        fn triangle(&mut self, tri: u32, leaf_tmin: i64) {
            self.tris.push((tri, leaf_tmin));
        }
        fn node(&mut self, node: u32) {
            self.nodes.push(node);
        }
    }

    fn run(m: &Module, sim: &mut Sim, ray: &GridRay, id: u64) -> Trace {
        let port = |name: &str| m.handle(m.inputs.iter().copied().find(|&i| m.sig(i).name == name).unwrap());
        let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
        sim.set(port("ray_valid"), 1);
        sim.set(port("ray_id"), id as i128);
        for (k, a) in ["x", "y", "z"].iter().enumerate() {
            sim.set(port(&format!("o{a}")), ray.o[k] as i128);
            sim.set(port(&format!("inv{a}")), ray.inv[k]);
        }
        assert_eq!(sim.get(out("ray_ready")), 1);
        sim.tick();
        sim.set(port("ray_valid"), 0);
        let mut t = Trace::default();
        for _ in 0..1_000_000 {
            if sim.get(out("visit")) == 1 {
                t.nodes.push(sim.get(out("visit_node")) as u32);
            }
            t.max_stack = t.max_stack.max(sim.get(out("stack_depth")) as u32);
            sim.tick();
            if sim.get(out("emit_valid")) == 1 {
                if sim.get(out("emit_end")) == 1 {
                    assert_eq!(sim.get(out("emit_id")), id as i128);
                    return t;
                }
                t.tris.push((sim.get(out("emit_tri")) as u32, sim.get(out("emit_tmin")) as i64));
            }
        }
        panic!("no end token");
    }

    /// Every ray of a small frame (hits, misses, grazing rays) through the FSM: the same node
    /// visits and the same triangle stream as `Golden::walk`, ray after ray in one simulation;
    /// at three clock targets (products of latency 1 to 6), which the machine follows by the
    /// unit's valid bits.
    #[test]
    fn visits_what_the_golden_walk_visits_in_its_order() {
        let cornell = Params { n: 20, m: 20, ..Params::default() };
        for (name, params, mhz) in
            [("teapot", Params::default(), 150), ("cornell", cornell, 75), ("cornell", cornell, 250)]
        {
            let scene = Scene::load(&SceneSource::Builtin(name.into()), &params).unwrap();
            let g = Golden::new(&scene);
            let roms = SceneRoms::of(&scene);
            let m = traverse_core(&TraverseParams::new(&roms, 16, ClockTarget(mhz)), &roms);
            let mut sim = Sim::new(&m);
            let cam = Camera::default_for(&scene, 24, 24);
            let mut rays = 0;
            for py in 0..24 {
                for px in 0..24 {
                    let Some(q) = quantize_ray(&scene, &g, &cam.ray(px, py)) else { continue };
                    let mut want = Trace::default();
                    want.max_stack = g.walk(&scene, &q.ray, &mut want).max_stack;
                    let got = run(&m, &mut sim, &q.ray, (py * 24 + px) as u64);
                    assert_eq!(got, want, "{name} at {mhz} MHz pixel {px},{py}");
                    rays += 1;
                }
            }
            assert!(rays > 300, "{rays}");
        }
    }
}
