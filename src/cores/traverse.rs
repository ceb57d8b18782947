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
//! Ring length P = N + L + 2 clocks (18 at the default 150 MHz with block ROMs): a slot steps
//! once per P clocks, so K ≥ P slots keep the ring full when no slot is parked.
//!
//! Slots: a free-slot bit vector; the top takes the lowest free slot (`alloc`) and writes the
//! ray's origin and reciprocal direction into the ray RAMs, and later the ray's scene-box exit
//! distance comes in through the new-ray queue (`new_*`). A slot is freed by the top when the
//! ray's result has left the core (`free_*`), so a slot's best hit is never read after reuse.

use super::brom::{bram, read_cycles};
use super::clock::ClockTarget;
use super::fifo::fifo;
use super::mul::MulStyle;
use super::plane::{PlaneIssue, plane_unit};
use super::{lowest_set, lt_chain, onehot};
use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use crate::scene::rom::{self, Field, Word, rom_addr_bits};

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
    /// Ray slots of the unit: rays it holds at once, each with its own registers and stack.
    pub slots: u32,
    /// The scene's tag (`SceneRoms::tag`), in the names of the modules built for the scene.
    pub scene_tag: String,
}

impl TraverseParams {
    pub fn new(scene: &SceneRoms, id_width: u32, target: ClockTarget, slots: u32) -> TraverseParams {
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
            slots,
            scene_tag: scene.tag(),
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
    /// Bits of a slot number within the unit.
    pub fn slot_bits(&self) -> u32 {
        rom::rom_addr_bits(self.slots as usize)
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

/// A token's fields in the ring.
#[derive(Clone, Copy)]
struct Token<'b> {
    valid: S<'b>,
    slot: S<'b>,
    node: S<'b>,
    tmin: S<'b>,
    tmax: S<'b>,
    sp: S<'b>,
}

/// The unit. Inputs: the ray RAM write (`ray_we`, `ray_slot`, ox, oy, oz, invx, invy, invz),
/// a new ray's box exit (`new_valid`, `new_slot`, `new_tmax`, `new_miss`), a leaf merged
/// (`merge_valid`, `merge_slot`, `merge_hit`, `merge_limit` = best t + 8, `merge_sp`), a slot
/// freed (`free_valid`, `free_slot`), `alloc` (the top takes `free_slot_out`), `leaf_pop` and
/// `done_pop` (the heads of the leaf and done queues are taken; the pop takes effect a clock
/// later, so the head is not taken again in the next clock), `node_word` (the node ROM's
/// word at `node_addr`, `node_rom_cycles` after it). Outputs: `node_addr`, the lowest free slot
/// (`has_free`, `free_slot_out`), the leaf queue's head (`leaf_valid`, `leaf_slot`, `leaf_first`,
/// `leaf_count`, `leaf_tmin`, `leaf_sp`), the done queue's head (`done_valid`, `done_slot`), and
/// observations: `visit` (a node visited in N, `visit_slot`, `visit_node`), `cull`, `depth`
/// (the stack depth in N), `occupied` (slots holding a ray).
pub fn traverse_core(p: &TraverseParams, scene: &SceneRoms) -> Module {
    let ((node_l, node_words), (_, leaf_words)) = (&scene.node, &scene.leaf);
    let k = p.slots;
    assert!((1..=64).contains(&k), "1 to 64 slots per unit");
    let b = Builder::new(&format!("fxrt_traverse_k{k}_{}", p.scene_tag));
    let (n, dist, sb, spw) = (p.n, p.dist_ty(), p.slot_bits(), p.sp_width());
    let slot_ty = Ty::u(sb);
    let node_bits = rom_addr_bits(node_words.len());
    let leaf_bits = rom_addr_bits(leaf_words.len());
    let count_w = node_l.field("count").width;
    let bit = Ty::BIT;

    let ray_we = b.input("ray_we", bit);
    let ray_slot = b.input("ray_slot", slot_ty);
    let o_in = ["ox", "oy", "oz"].map(|s| b.input(s, Ty::u(n)));
    let inv_in = ["invx", "invy", "invz"].map(|s| b.input(s, Ty::s(p.inv_width())));
    let new_valid = b.input("new_valid", bit);
    let new_slot = b.input("new_slot", slot_ty);
    let new_tmax = b.input("new_tmax", dist);
    let new_miss = b.input("new_miss", bit);
    let merge_valid = b.input("merge_valid", bit);
    let merge_slot = b.input("merge_slot", slot_ty);
    let merge_hit = b.input("merge_hit", bit);
    let merge_limit = b.input("merge_limit", dist);
    let merge_sp = b.input("merge_sp", Ty::u(spw));
    let free_valid = b.input("free_valid", bit);
    let free_slot = b.input("free_slot", slot_ty);
    let alloc = b.input("alloc", bit);
    let leaf_pop = b.input("leaf_pop", bit);
    let done_pop = b.input("done_pop", bit);
    // The node ROM is the core's (two units share one through a block RAM's two ports): the
    // unit sends the address in C and gets the word `node_rom_cycles` later, in N.
    let word = b.input("node_word", Ty::u(node_l.width));

    // The ray RAMs: written when the top accepts a ray, read in N for the plane units.
    let o_mem = b.ram("ray_o", 3 * n, vec![0; k as usize]);
    b.ram_write(o_mem, ray_we, ray_slot, b.cat(&[o_in[2], o_in[1], o_in[0]]));
    let inv_mem = [0, 1, 2].map(|a| {
        let mem = b.ram(&format!("ray_inv{}", ["x", "y", "z"][a]), p.inv_width(), vec![0; k as usize]);
        b.ram_write(mem, ray_we, ray_slot, inv_in[a].unsigned());
        mem
    });

    // Free slots: a bit per slot, the lowest free one registered (one clock stale, so a slot
    // just taken is masked for a clock by `just_alloc`).
    let all = (1i128 << k) - 1;
    let free_bits = b.reg("free_bits", Ty::u(k), Some(all));
    let (any_free, lowest) = lowest_set(&(0..k).map(|i| free_bits.bit(i)).collect::<Vec<_>>(), sb);
    // Reset to what they hold after a clock of reset (all free, slot 0), so a core that idles
    // for a while after reset behaves as one that does not.
    let free_any_r = b.reg("free_any_r", bit, Some(1));
    b.next(free_any_r, any_free.name("free_any_c"));
    let free_idx_r = b.reg("free_idx_r", slot_ty, Some(0));
    b.next(free_idx_r, lowest.name("free_idx_c"));
    let just_alloc = b.reg("just_alloc", bit, Some(0));
    b.next(just_alloc, alloc);
    let taken = alloc.select(onehot(ray_slot, k), b.konst(Ty::u(k), 0)).name("taken_mask");
    let freed = free_valid.select(onehot(free_slot, k), b.konst(Ty::u(k), 0)).name("freed_mask");
    b.next(free_bits, (free_bits & !taken) | freed);
    let occupied = b.reg("occupied_r", Ty::u(sb + 1), Some(0));
    b.next(occupied, occupied + alloc.resize(sb + 1) - free_valid.resize(sb + 1));

    // The queues into the ring: rays back from a leaf (slot, sp) and new rays (slot, tmax, miss).
    let ring_g_valid = b.wire("ring_g_valid", bit);
    let unpark_pop = b.wire("unpark_pop", bit);
    let new_pop = b.wire("new_pop", bit);
    let unpark = fifo(&b, "unpark_q", sb + spw, k, merge_valid, b.cat(&[merge_slot, merge_sp]), unpark_pop);
    let newq = fifo(
        &b,
        "new_q",
        sb + dist.width + 1,
        k,
        new_valid,
        b.cat(&[new_slot, new_tmax.unsigned(), new_miss]),
        new_pop,
    );
    // E: a queued ray enters when the token now in G will not return (R empty in A).
    let take_unpark = (!ring_g_valid & unpark.nonempty).name("take_unpark");
    let take_new = (!ring_g_valid & !unpark.nonempty & newq.nonempty).name("take_new");
    b.drive(unpark_pop, take_unpark);
    b.drive(new_pop, take_new);
    let q_valid = b.valid_delay("q_valid", take_unpark | take_new);
    let q_new = b.delay("q_new", take_new);
    let q_slot = b.delay("q_slot", take_unpark.select(unpark.head.slice(spw, sb), newq.head.slice(dist.width + 1, sb)));
    // An unparked ray's stack pointer, with sp = 0 and sp − 1 made here, so that A is muxes.
    let head_sp = unpark.head.slice(0, spw);
    let q_sp = b.delay("q_sp", head_sp);
    let q_sp_zero = b.delay("q_sp_zero", head_sp.eq(0));
    let q_sp_m1 = b.delay("q_sp_m1", head_sp - 1);
    let q_tmax = b.delay("q_tmax", newq.head.slice(1, dist.width).signed());
    let q_miss = b.delay("q_miss", newq.head.bit(0));

    // R: the token back from G (a wire here, a register below), with sp = 0 and sp − 1 made in G.
    let r_valid = b.reg("r_valid", bit, Some(0));
    let r_pop = b.reg("r_pop", bit, None);
    let r_sp_zero = b.reg("r_sp_zero", bit, None);
    let r_sp_m1 = b.reg("r_sp_m1", Ty::u(spw), None);
    let r = Token {
        valid: r_valid,
        slot: b.reg("r_slot", slot_ty, None),
        node: b.reg("r_node", Ty::u(node_bits), None),
        tmin: b.reg("r_tmin", dist, None),
        tmax: b.reg("r_tmax", dist, None),
        sp: b.reg("r_sp", Ty::u(spw), None),
    };

    // A.
    let a_valid = (r_valid | q_valid).name("a_valid");
    let a_slot = r_valid.select(r.slot, q_slot).name("a_slot");
    let a_new = (!r_valid & q_new).name("a_new");
    let a_pop = r_valid.select(r_pop, !q_new).name("a_pop");
    let a_sp = r_valid.select(r.sp, q_new.select(q_sp.k(0), q_sp)).name("a_sp");
    let a_sp_zero = r_valid.select(r_sp_zero, q_new | q_sp_zero).name("a_sp_zero");
    let a_sp_m1 = r_valid.select(r_sp_m1, q_sp_m1).name("a_sp_m1");
    let a_done = (a_valid & ((a_pop & a_sp_zero) | (a_new & q_miss))).name("a_done");
    let a_from_stack = (a_pop & !a_sp_zero).name("a_from_stack");
    let stack_bits = rom_addr_bits(p.stack_depth as usize);
    // The stack: a block RAM read in two clocks (`brom::bram`), written in G.
    let stack_w = node_bits + 2 * dist.width;
    let stack_addr_ty = Ty::u(sb + stack_bits);
    let (push_w, push_addr, push_data) =
        (b.wire("stack_we", bit), b.wire("stack_waddr", stack_addr_ty), b.wire("stack_wdata", Ty::u(stack_w)));
    let raddr = b.cat(&[a_slot, a_sp_m1.resize(stack_bits)]).name("stack_raddr");
    // One stack of 2^stack_bits words per slot number the address can hold: a slot number has
    // at least one bit, so one slot still takes two stacks' worth of address space.
    let stack_words = (k.max(2) as usize) << stack_bits;
    let top =
        bram(&b, "u_stack", &format!("stack_w{stack_w}"), stack_w, stack_words, push_w, push_addr, push_data, raddr);
    let bt = Token {
        valid: b.valid_delay("b_valid", (a_valid & !a_done).name("a_live")),
        slot: b.delay("b_slot", a_slot),
        node: b.delay("b_node", r_valid.select(r.node, r.node.k(0))),
        tmin: b.delay("b_tmin", r_valid.select(r.tmin, r.tmin.k(0))),
        tmax: b.delay("b_tmax", r_valid.select(r.tmax, q_tmax)),
        sp: b.delay("b_sp", a_from_stack.select(a_sp_m1, a_sp)),
    };
    let b_from_stack = b.delay_line("b_from_stack", a_from_stack, 2);
    // B waits a clock for the stack word (the block's output register).
    let bt = Token {
        valid: b.valid_delay("b2_valid", bt.valid),
        slot: b.delay("b2_slot", bt.slot),
        node: b.delay("b2_node", bt.node),
        tmin: b.delay("b2_tmin", bt.tmin),
        tmax: b.delay("b2_tmax", bt.tmax),
        sp: b.delay("b2_sp", bt.sp),
    };
    // The top's pops arrive a clock late (registered here: the top's arbiter sits across the
    // die), so it does not take from a queue again in the clock after it took.
    let done = fifo(&b, "done_q", sb, k, a_done, a_slot, b.valid_delay("done_pop_r", done_pop));

    // B: a popped entry (far node, far_min, tmax) from the stack word.
    let top_tmax = top.slice(0, dist.width).signed();
    let top_tmin = top.slice(dist.width, dist.width).signed();
    let top_node = top.slice(2 * dist.width, node_bits);
    let c = Token {
        valid: b.valid_delay("c_valid", bt.valid),
        slot: b.delay("c_slot", bt.slot),
        node: b.delay("c_node", b_from_stack.select(top_node, bt.node)),
        tmin: b.delay("c_tmin", b_from_stack.select(top_tmin, bt.tmin)),
        tmax: b.delay("c_tmax", b_from_stack.select(top_tmax, bt.tmax)),
        sp: b.delay("c_sp", bt.sp),
    };

    // C: the node ROM read, and the cull test: lower_t(tmin) > best t ⟺ tmin − tmin/64 >
    // best t + 8 (`golden::lower_t`), only when the slot has a best hit.
    let nrc = p.node_rom_cycles;
    let limit_mem = b.ram("cull_limit", dist.width, vec![0; k as usize]);
    b.ram_write(limit_mem, (merge_valid & merge_hit).name("limit_we"), merge_slot, merge_limit.unsigned());
    let limit = b.read("limit_q", limit_mem, c.slot).signed();
    let has_best = b.reg("has_best", Ty::u(k), Some(0));
    let x = b.delay("cull_x", (c.tmin - (c.tmin >> 6)).name("tmin_less"));
    let hb = b.delay(
        "cull_has_best",
        b.case(c.slot, &(0..k).map(|i| (i as u128, has_best.bit(i))).collect::<Vec<_>>(), b.konst(bit, 0))
            .name("slot_has_best"),
    );
    let culled = b.delay("culled", (hb & lt_chain(limit, x)).name("culled_c"));
    let culled = b.delay_line("culled_n", culled, nrc - 2);
    let set_best = (merge_valid & merge_hit).select(onehot(merge_slot, k), b.konst(Ty::u(k), 0)).name("best_set");
    let clear_best = (a_new & a_valid).select(onehot(a_slot, k), b.konst(Ty::u(k), 0)).name("best_clear");
    b.next(has_best, (has_best & !clear_best) | set_best);

    // N: the node word.
    let nt = Token {
        valid: b.valid_line("n_valid", c.valid, nrc),
        slot: b.delay_line("n_slot", c.slot, nrc),
        node: b.delay_line("n_node", c.node, nrc),
        tmin: b.delay_line("n_tmin", c.tmin, nrc),
        tmax: b.delay_line("n_tmax", c.tmax, nrc),
        sp: b.delay_line("n_sp", c.sp, nrc),
    };
    let nf = |name: &str| field(&format!("nw_{name}"), word, node_l.field(name), 0);
    let (w_axis, w_clip0, w_clip1, w_child, w_first, w_count) =
        (nf("axis"), nf("clip0"), nf("clip1"), nf("child"), nf("first"), nf("count"));
    let w_leaf = w_axis.eq(3).name("nw_is_leaf");
    let visit = (nt.valid & !culled).name("visit_c");
    let is_inner = (visit & !w_leaf).name("is_inner");
    let leaf_push = (visit & w_leaf & w_count.ne(0)).name("leaf_push");
    let leaf_in =
        b.cat(&[nt.slot, w_first.resize(leaf_bits), w_count, nt.tmin.unsigned().resize(p.tmin_width()), nt.sp]);
    let leafq = fifo(&b, "leaf_q", leaf_in.width(), k, leaf_push, leaf_in, b.valid_delay("leaf_pop_r", leaf_pop));

    // The plane units, one per clip plane, fed the slot's ray from the ray RAMs (read in N, in
    // the units' second stage in N + 1).
    let o_word = b.read("ray_o_q", o_mem, nt.slot);
    let o = [0, 1, 2].map(|a| o_word.slice(a * n, n));
    let inv = [0, 1, 2].map(|a| b.read(&format!("ray_inv{}_q", ["x", "y", "z"][a]), inv_mem[a], nt.slot).signed());
    let pu0 = plane_unit(
        &b,
        n,
        p.c,
        o,
        inv,
        PlaneIssue { valid: is_inner, last: is_inner.k(0), plane: w_clip0, axis: w_axis },
        p.product,
    );
    let pu1 = plane_unit(
        &b,
        n,
        p.c,
        o,
        inv,
        PlaneIssue { valid: is_inner, last: is_inner.k(1), plane: w_clip1, axis: w_axis },
        p.product,
    );
    let l = pu0.latency;
    assert!(l >= 4, "the decision limits need 3 cycles after N");
    let axis1 = b.delay("axis_n1", w_axis);
    let negative = b.delay_line("negative", b.pick(axis1, inv).msb().name("negative_c"), l - 1);

    // N → F: the token rides along; the limits are made on the way (as `inner_step`'s compares,
    // every one a strict less-than; when tmin > tmax no distance passes any limit).
    let ring = (nt.valid & !leaf_push).name("n_stays");
    let f_valid = b.valid_line("f_valid", ring, l);
    let f_inner = b.delay_line("f_inner", is_inner, l);
    let f_slot = b.delay_line("f_slot", nt.slot, l);
    let f_tmin = b.delay_line("f_tmin", nt.tmin, l);
    let f_tmax = b.delay_line("f_tmax", nt.tmax, l);
    let f_sp = b.delay_line("f_sp", nt.sp, l);
    let f_child = b.delay_line("f_child", w_child, l);
    let neg1 = b.delay("negative_n1", b.pick(axis1, inv).msb());
    let (tmin1, tmax1) = (b.delay("tmin_n1", nt.tmin), b.delay("tmax_n1", nt.tmax));
    let tmax_p1 = b.delay("tmax_p1", (nt.tmax + 1).name("tmax_plus_1"));
    let tmin_m1 = b.delay("tmin_m1", (nt.tmin - 1).name("tmin_minus_1"));
    let tmin_le_tmax = b.delay("tmin_le_tmax", lt_chain(tmin1, tmax_p1).name("tmin_le_tmax_c"));
    let (tmin2, tmax2, tmax_p1_2, tmin_m1_2) = (
        b.delay("tmin_n2", tmin1),
        b.delay("tmax_n2", tmax1),
        b.delay("tmax_p1_n2", tmax_p1),
        b.delay("tmin_m1_n2", tmin_m1),
    );
    let never_below = tmax2.k(-(1i128 << (n + 2)));
    let never_above = tmax2.k((1i128 << (n + 2)) - 1);
    let limit_reg = |name: &str, if_negative: S<'_>, if_positive: S<'_>, never: S<'_>| {
        let x = tmin_le_tmax.select(neg1.select(if_negative, if_positive), never);
        b.delay_line(name, b.delay(&format!("{name}_n3"), x.name(&format!("{name}_c"))), l - 3)
    };
    let d0_hi = limit_reg("d0_hi", tmax_p1_2, tmax2, never_below);
    let d0_lo = limit_reg("d0_lo", tmin2, tmin_m1_2, never_above);
    let d1_hi = limit_reg("d1_hi", tmax2, tmax_p1_2, never_below);
    let d1_lo = limit_reg("d1_lo", tmin_m1_2, tmin2, never_above);

    // F: the compares, registered by role for G.
    let (d0, d1) = (pu0.t, pu1.t);
    let d0_below = lt_chain(d0, d0_hi).name("d0_below");
    let d0_above = lt_chain(d0_lo, d0).name("d0_above");
    let d1_below = lt_chain(d1, d1_hi).name("d1_below");
    let d1_above = lt_chain(d1_lo, d1).name("d1_above");
    let reg = |name: &str, if_negative: S<'_>, if_positive: S<'_>| {
        b.delay(name, negative.select(if_negative, if_positive).name(&format!("{name}_c")))
    };
    let near_lt_tmax = reg("near_lt_tmax", d1_below, d0_below);
    let far_gt_tmin = reg("far_gt_tmin", d0_above, d1_above);
    let go_near = reg("go_near", d1_above, d0_above);
    let go_far = reg("go_far", d0_below, d1_below);
    let near_end = b.delay("near_end", negative.select(d1, d0));
    let far_start = b.delay("far_start", negative.select(d0, d1));
    let g = Token {
        valid: b.valid_delay("g_valid", f_valid),
        slot: b.delay("g_slot", f_slot),
        node: b.delay("g_child", f_child),
        tmin: b.delay("g_tmin", f_tmin),
        tmax: b.delay("g_tmax", f_tmax),
        sp: b.delay("g_sp", f_sp),
    };
    let g_inner = b.delay("g_inner", f_inner);
    let g_neg = b.delay("g_negative", negative);

    // G: the step.
    b.drive(ring_g_valid, g.valid);
    let child_b = g.node + 1;
    let near = g_neg.select(child_b, g.node).resize(node_bits).name("near");
    let far = g_neg.select(g.node, child_b).resize(node_bits).name("far");
    let near_max = near_lt_tmax.select(near_end, g.tmax).name("near_max");
    let far_min = far_gt_tmin.select(far_start, g.tmin).name("far_min");
    let (enter_near, enter_far) =
        ((g_inner & go_near).name("enter_near"), (g_inner & !go_near & go_far).name("enter_far"));
    let push = (enter_near & go_far).name("push");
    b.drive(push_w, push);
    b.drive(push_addr, b.cat(&[g.slot, g.sp.resize(stack_bits)]));
    b.drive(push_data, b.cat(&[far, far_min.unsigned(), g.tmax.unsigned()]));
    b.next(r_valid, g.valid);
    b.next(r_pop, !(enter_near | enter_far));
    b.next(r.slot, g.slot);
    b.next(r.node, enter_near.select(near, far));
    b.next(r.tmin, enter_far.select(far_min, g.tmin));
    b.next(r.tmax, enter_near.select(near_max, g.tmax));
    b.next(r.sp, push.select(g.sp + 1, g.sp));
    b.next(r_sp_zero, !push & g.sp.eq(0));
    b.next(r_sp_m1, push.select(g.sp, g.sp - 1));

    b.output("node_addr", c.node);
    b.output("has_free", (free_any_r & !just_alloc).name("has_free_c"));
    b.output("free_slot_out", free_idx_r);
    let lh = leafq.head;
    let mut at = 0;
    let mut take = |w: u32| {
        let s = lh.slice(at, w);
        at += w;
        s
    };
    let (l_sp, l_tmin, l_count, l_first, l_slot) =
        (take(spw), take(p.tmin_width()), take(count_w), take(leaf_bits), take(sb));
    b.output("leaf_valid", leafq.nonempty);
    b.output("leaf_slot", l_slot);
    b.output("leaf_first", l_first);
    b.output("leaf_count", l_count);
    b.output("leaf_tmin", l_tmin);
    b.output("leaf_sp", l_sp);
    b.output("done_valid", done.nonempty);
    b.output("done_slot", done.head);
    b.output("visit", visit);
    b.output("visit_slot", nt.slot);
    b.output("visit_node", nt.node);
    b.output("cull", (nt.valid & culled).name("cull_c"));
    b.output("depth", nt.sp);
    b.output("occupied", occupied);
    b.finish()
}
