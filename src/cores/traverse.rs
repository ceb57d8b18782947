//! The BIH traversal unit (seed 001 §3.4, figure 3.6, table 3.1): a state machine that takes
//! one ray at a time and emits, one per clock, every triangle of every leaf the ray visits,
//! in exactly the order of `Golden::walk` (near child first, far child pushed, no early out).
//! The node and leaf ROMs and the stack RAM are synchronous block memories.
//!
//! States (one cycle each unless noted):
//! - `idle`: `ray_ready`; a valid ray is latched.
//! - `aabb` (3 cycles, one axis each): the scene-box exit distance tmax; a ray that misses the
//!   box (tmax < 0) goes straight to `done`, else node 0 with tmin = 0.
//! - `node`: the node word is on the ROM output. A leaf loads its first entry and count; an
//!   inner node latches its fields and computes d0, the distance to clip0.
//! - `inner`: d1 to clip1, then `bih::inner_step`'s decision: push the far child and enter the
//!   near one, enter one child, or pop.
//! - `leaf` (count cycles): one leaf entry per clock.
//! - `pop`: the top of the stack (always read ahead) is loaded, or `done` when it is empty.
//! - `done`: an end token follows the ray's last triangle, so the closest-hit unit knows the
//!   ray is complete when the token leaves the in-order pipeline.
//!
//! The node ROM is addressed by the node register's next value, so its word is ready in the
//! cycle the FSM enters `node`. One plane-distance unit (one multiplier) serves all states.

use super::intersect::{as_signed_wider, pick};
use crate::rtl::{Module, Sig, Ty, UnOp};
use crate::scene::images::SceneRoms;
use crate::scene::rom::rom_addr_bits;
use crate::scene::rom::{self, Field, Layout, Word};

pub const IDLE: i128 = 0;
pub const AABB: i128 = 1;
pub const NODE: i128 = 2;
pub const INNER: i128 = 3;
pub const LEAF: i128 = 4;
pub const POP: i128 = 5;
pub const DONE: i128 = 6;

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
}

impl TraverseParams {
    pub fn new(scene: &SceneRoms, id_width: u32) -> TraverseParams {
        let p = &scene.params;
        TraverseParams {
            n: p.n,
            m: p.m,
            c: p.c,
            id_width,
            stack_depth: p.stack_depth,
            box_hi: scene.box_hi,
            tri_bits: rom::addr_bits(scene.tri_count()),
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
pub fn field(m: &mut Module, name: &str, word: Sig, f: &Field, word_lsb: u32) -> Sig {
    let raw = m.slice(name, word, f.lsb - word_lsb, f.width);
    if f.signed { m.un(&format!("{name}_s"), UnOp::AsSigned, raw) } else { raw }
}

/// Ports of the unit, in order: inputs, then outputs.
pub fn traverse_core(p: &TraverseParams, scene: &SceneRoms) -> Module {
    let ((node_l, node_words), (leaf_l, leaf_words)) = (&scene.node, &scene.leaf);
    let mut m = Module::new("fxrt_traverse");
    let (n, dist) = (p.n, p.dist_ty());
    let ray_valid = m.input("ray_valid", Ty::BIT);
    let ray_id = m.input("ray_id", Ty::u(p.id_width));
    let o_in: Vec<Sig> = ["ox", "oy", "oz"].iter().map(|s| m.input(s, Ty::u(n))).collect();
    let inv_in: Vec<Sig> = ["invx", "invy", "invz"].iter().map(|s| m.input(s, Ty::s(p.inv_width()))).collect();

    let state = m.reg("state", Ty::u(3), Some(IDLE));
    let is = |m: &mut Module, name: &str, k: i128| m.eq_k(name, state, k);
    let in_idle = is(&mut m, "in_idle", IDLE);
    let in_aabb = is(&mut m, "in_aabb", AABB);
    let in_node = is(&mut m, "in_node", NODE);
    let in_inner = is(&mut m, "in_inner", INNER);
    let in_leaf = is(&mut m, "in_leaf", LEAF);
    let in_pop = is(&mut m, "in_pop", POP);
    let in_done = is(&mut m, "in_done", DONE);
    let accept = m.and("accept", in_idle, ray_valid);

    // The ray, latched on accept.
    let id_r = m.reg("ray_id_r", ray_id.ty, None);
    m.connect(id_r, ray_id, Some(accept));
    let o: Vec<Sig> = o_in
        .iter()
        .zip(["ox_r", "oy_r", "oz_r"])
        .map(|(s, name)| {
            let r = m.reg(name, s.ty, None);
            m.connect(r, *s, Some(accept));
            r
        })
        .collect();
    let inv: Vec<Sig> = inv_in
        .iter()
        .zip(["invx_r", "invy_r", "invz_r"])
        .map(|(s, name)| {
            let r = m.reg(name, s.ty, None);
            m.connect(r, *s, Some(accept));
            r
        })
        .collect();
    let (o, inv) = ([o[0], o[1], o[2]], [inv[0], inv[1], inv[2]]);

    // Node ROM, addressed by the node register's next value.
    let node_bits = rom_addr_bits(node_words.len());
    let node = m.reg("node", Ty::u(node_bits), Some(0));
    let node_next = m.wire("node_next", node.ty);
    let node_rom = m.rom("node_rom", node_l.width, node_words.iter().map(|w| word_bits(w, 0, node_l.width)).collect());
    let word = m.rom_read("node_word", node_rom, node_next);
    let nf = |m: &mut Module, name: &str, l: &Layout| field(m, &format!("nw_{name}"), word, l.field(name), 0);
    let w_axis = nf(&mut m, "axis", node_l);
    let w_clip0 = nf(&mut m, "clip0", node_l);
    let w_clip1 = nf(&mut m, "clip1", node_l);
    let w_child = nf(&mut m, "child", node_l);
    let w_first = nf(&mut m, "first", node_l);
    let w_count = nf(&mut m, "count", node_l);
    let w_leaf = m.eq_k("nw_is_leaf", w_axis, 3);

    // Registers of the inner-node step.
    let axis_r = m.reg("axis_r", Ty::u(2), None);
    let clip1_r = m.reg("clip1_r", Ty::u(n), None);
    let child_r = m.reg("child_r", w_child.ty, None);
    let d0_r = m.reg("d0_r", dist, None);
    let aabb_k = m.reg("aabb_k", Ty::u(2), None);
    let tmin = m.reg("tmin", dist, None);
    let tmax = m.reg("tmax", dist, None);

    // The plane-distance unit: ((plane − O_axis) · inv_axis) >> C, clamped to [−1, 2^(n+1)].
    let hi: Vec<Sig> = (0..3).map(|k| m.konst(&format!("box_hi_{k}"), Ty::u(n), p.box_hi[k] as i128)).collect();
    let zero_n = m.konst("plane_zero", Ty::u(n), 0);
    let aabb_inv = pick(&mut m, "aabb_inv", aabb_k, inv);
    let aabb_neg = m.bit("aabb_neg", aabb_inv, p.inv_width() - 1);
    let aabb_hi = pick(&mut m, "aabb_hi", aabb_k, [hi[0], hi[1], hi[2]]);
    let aabb_plane = m.mux("aabb_plane", aabb_neg, zero_n, aabb_hi);
    let pu_axis_a = m.mux("pu_axis_a", in_node, w_axis, axis_r);
    let pu_axis = m.mux("pu_axis", in_aabb, aabb_k, pu_axis_a);
    let pu_plane_a = m.mux("pu_plane_a", in_node, w_clip0, clip1_r);
    let pu_plane = m.mux("pu_plane", in_aabb, aabb_plane, pu_plane_a);
    let pu_o = pick(&mut m, "pu_o", pu_axis, o);
    let pu_inv = pick(&mut m, "pu_inv", pu_axis, inv);
    let plane_s = as_signed_wider(&mut m, "pu_plane_s", pu_plane);
    let o_s = as_signed_wider(&mut m, "pu_o_s", pu_o);
    let delta = m.sub("pu_delta", plane_s, o_s);
    let prod = m.mul("pu_prod", delta, pu_inv);
    let shifted = m.shr("pu_shifted", prod, p.c);
    let minus1 = m.konst("pu_minus1", prod.ty, -1);
    let t_sat = m.konst("pu_sat", prod.ty, 1i128 << (n + 1));
    let below = m.lt("pu_below", shifted, minus1);
    let above = m.lt("pu_above", t_sat, shifted);
    let clamped_a = m.mux("pu_clamp_a", below, minus1, shifted);
    let clamped = m.mux("pu_clamp", above, t_sat, clamped_a);
    let plane_t = m.resize("plane_t", clamped, dist.width);

    // aabb: tmax = min over the axes; the ray misses the box when it ends below 0.
    let k0 = m.eq_k("aabb_first", aabb_k, 0);
    let k2 = m.eq_k("aabb_last", aabb_k, 2);
    let lower = m.lt("aabb_lower", plane_t, tmax);
    let keep_first = m.or("aabb_take", k0, lower);
    let aabb_tmax = m.mux("aabb_tmax", keep_first, plane_t, tmax);
    let zero_d = m.konst("dist_zero", dist, 0);
    let aabb_miss = m.lt("aabb_miss", aabb_tmax, zero_d);
    let one2 = m.konst("aabb_one", Ty::u(2), 1);
    let aabb_k_inc = m.add("aabb_k_inc", aabb_k, one2);
    let zero2 = m.konst("aabb_zero", Ty::u(2), 0);
    let aabb_k_next = m.mux("aabb_k_next", in_aabb, aabb_k_inc, zero2);
    m.connect(aabb_k, aabb_k_next, None);

    // inner: bih::inner_step with d0 (registered) and d1 (this cycle).
    let inv_ax = pick(&mut m, "inner_inv", axis_r, inv);
    let negative = m.bit("inner_negative", inv_ax, p.inv_width() - 1);
    let one_c = m.konst("child_one", child_r.ty, 1);
    let child_b = m.add("child_right", child_r, one_c);
    let near = m.mux("near", negative, child_b, child_r);
    let far = m.mux("far", negative, child_r, child_b);
    let near_end = m.mux("near_end", negative, plane_t, d0_r);
    let far_start = m.mux("far_start", negative, d0_r, plane_t);
    let ne_lt = m.lt("near_end_lt", near_end, tmax);
    let near_max = m.mux("near_max", ne_lt, near_end, tmax);
    let fs_gt = m.lt("far_start_gt", tmin, far_start);
    let far_min = m.mux("far_min", fs_gt, far_start, tmin);
    let go_near = m.le("go_near", tmin, near_max);
    let go_far = m.le("go_far", far_min, tmax);
    let both = m.and("go_both", go_near, go_far);
    let push = m.and("push", in_inner, both);
    let not_near = m.not("not_near", go_near);
    let far_only = m.and("far_only", not_near, go_far);
    let to_near = m.and("to_near", in_inner, go_near);
    let to_far = m.and("to_far", in_inner, far_only);

    // Stack: (far node, far_min, tmax) at sp on a push; the top (sp − 1) is always read ahead.
    let sp = m.reg("sp", Ty::u(p.sp_width()), Some(0));
    let stack_bits = rom_addr_bits(p.stack_depth as usize);
    let entry_w = node_bits + 2 * dist.width;
    let stack = m.ram("stack", entry_w, vec![0; p.stack_depth as usize]);
    let far_min_u = m.un("push_far_min", UnOp::AsUnsigned, far_min);
    let tmax_u = m.un("push_tmax", UnOp::AsUnsigned, tmax);
    let far_n = m.resize("push_far", far, node_bits);
    let entry = m.concat("push_entry", &[far_n, far_min_u, tmax_u]);
    let sp_addr = m.resize("sp_addr", sp, stack_bits);
    m.ram_write(stack, push, sp_addr, entry);
    let one_sp = m.konst("sp_one", sp.ty, 1);
    let sp_dec = m.sub("sp_dec", sp, one_sp);
    let top_addr = m.resize("top_addr", sp_dec, stack_bits);
    let top = m.rom_read("stack_top", stack, top_addr);
    let top_tmax_u = m.slice("top_tmax_u", top, 0, dist.width);
    let top_tmin_u = m.slice("top_tmin_u", top, dist.width, dist.width);
    let top_node = m.slice("top_node", top, 2 * dist.width, node_bits);
    let top_tmax = m.un("top_tmax", UnOp::AsSigned, top_tmax_u);
    let top_tmin = m.un("top_tmin", UnOp::AsSigned, top_tmin_u);
    let sp_empty = m.eq_k("sp_empty", sp, 0);
    let sp_nonempty = m.not("sp_nonempty", sp_empty);
    let popping = m.and("popping", in_pop, sp_nonempty);
    let sp_inc = m.add("sp_inc", sp, one_sp);
    let sp_a = m.mux("sp_a", push, sp_inc, sp);
    let sp_next = m.mux("sp_next", popping, sp_dec, sp_a);
    m.connect(sp, sp_next, None);

    // leaf: one entry per clock.
    let leaf_bits = rom_addr_bits(leaf_words.len());
    let leaf_ptr = m.reg("leaf_ptr", Ty::u(leaf_bits), None);
    let left = m.reg("leaf_left", w_count.ty, None);
    let one_l = m.konst("leaf_one", leaf_ptr.ty, 1);
    let ptr_inc = m.add("leaf_ptr_inc", leaf_ptr, one_l);
    let first = m.resize("leaf_first", w_first, leaf_bits);
    let enter_leaf = m.and("enter_leaf", in_node, w_leaf);
    let ptr_a = m.mux("leaf_ptr_a", in_leaf, ptr_inc, leaf_ptr);
    let ptr_next = m.mux("leaf_ptr_next", enter_leaf, first, ptr_a);
    m.connect(leaf_ptr, ptr_next, None);
    let one_cnt = m.konst("left_one", left.ty, 1);
    let left_dec = m.sub("left_dec", left, one_cnt);
    let left_a = m.mux("left_a", in_leaf, left_dec, left);
    let left_next = m.mux("left_next", enter_leaf, w_count, left_a);
    m.connect(left, left_next, None);
    let last_entry = m.eq_k("leaf_last", left, 1);
    let empty_leaf = m.eq_k("leaf_empty", w_count, 0);

    // Inner-node fields, latched in `node`.
    let enter_inner = m.not("nw_inner", w_leaf);
    let latch_inner = m.and("latch_inner", in_node, enter_inner);
    m.connect(axis_r, w_axis, Some(latch_inner));
    m.connect(clip1_r, w_clip1, Some(latch_inner));
    m.connect(child_r, w_child, Some(latch_inner));
    m.connect(d0_r, plane_t, Some(latch_inner));

    // tmin / tmax.
    let aabb_end = m.and("aabb_end", in_aabb, k2);
    let tmin_a = m.mux("tmin_a", to_far, far_min, tmin);
    let tmin_b = m.mux("tmin_b", popping, top_tmin, tmin_a);
    let tmin_next = m.mux("tmin_next", aabb_end, zero_d, tmin_b);
    m.connect(tmin, tmin_next, None);
    let tmax_a = m.mux("tmax_a", to_near, near_max, tmax);
    let tmax_b = m.mux("tmax_b", popping, top_tmax, tmax_a);
    let tmax_next = m.mux("tmax_next", in_aabb, aabb_tmax, tmax_b);
    m.connect(tmax, tmax_next, None);

    // Node register: 0 after aabb, a child after inner, the popped node after pop.
    let near_n = m.resize("near_n", near, node_bits);
    let far_nn = m.resize("far_n", far, node_bits);
    let zero_node = m.konst("node_zero", node.ty, 0);
    let node_a = m.mux("node_a", to_near, near_n, node);
    let node_b = m.mux("node_b", to_far, far_nn, node_a);
    let node_c = m.mux("node_c", popping, top_node, node_b);
    let node_d = m.mux("node_d", aabb_end, zero_node, node_c);
    m.drive(node_next, node_d);
    m.connect(node, node_next, None);

    // Next state.
    let k = |m: &mut Module, name: &str, v: i128| m.konst(name, Ty::u(3), v);
    let s_idle = k(&mut m, "st_idle", IDLE);
    let s_aabb = k(&mut m, "st_aabb", AABB);
    let s_node = k(&mut m, "st_node", NODE);
    let s_inner = k(&mut m, "st_inner", INNER);
    let s_leaf = k(&mut m, "st_leaf", LEAF);
    let s_pop = k(&mut m, "st_pop", POP);
    let s_done = k(&mut m, "st_done", DONE);
    let from_idle = m.mux("from_idle", ray_valid, s_aabb, s_idle);
    let aabb_go = m.mux("aabb_go", aabb_miss, s_done, s_node);
    let from_aabb = m.mux("from_aabb", k2, aabb_go, s_aabb);
    let leaf_go = m.mux("leaf_go", empty_leaf, s_pop, s_leaf);
    let from_node = m.mux("from_node", w_leaf, leaf_go, s_inner);
    let any_child = m.or("any_child", go_near, go_far);
    let from_inner = m.mux("from_inner", any_child, s_node, s_pop);
    let from_leaf = m.mux("from_leaf", last_entry, s_pop, s_leaf);
    let from_pop = m.mux("from_pop", sp_empty, s_done, s_node);
    let state_next = m.case(
        "state_next",
        state,
        &[
            (IDLE as u128, from_idle),
            (AABB as u128, from_aabb),
            (NODE as u128, from_node),
            (INNER as u128, from_inner),
            (LEAF as u128, from_leaf),
            (POP as u128, from_pop),
        ],
        s_idle,
    );
    m.connect(state, state_next, None);

    // Emission, one cycle behind the FSM so it lines up with the leaf ROM's output.
    let leaf_rom = m.rom("leaf_rom", leaf_l.width, leaf_words.iter().map(|w| word_bits(w, 0, leaf_l.width)).collect());
    let tri = m.rom_read("leaf_tri", leaf_rom, leaf_ptr);
    let emit = m.or("emit", in_leaf, in_done);
    let emit_r = m.delay("emit_r", emit);
    let end_r = m.delay("end_r", in_done);
    let tmin_u = m.un("tmin_u", UnOp::AsUnsigned, tmin);
    let tmin_w = m.resize("tmin_w", tmin_u, p.tmin_width());
    let tmin_r = m.delay("tmin_r", tmin_w);
    let id_out = m.delay("id_r", id_r);
    let tri_w = m.resize("tri_w", tri, p.tri_bits);
    m.output("ray_ready", in_idle);
    m.output("emit_valid", emit_r);
    m.output("emit_end", end_r);
    m.output("emit_tri", tri_w);
    m.output("emit_tmin", tmin_r);
    m.output("emit_id", id_out);
    for (name, s) in ["ox", "oy", "oz"].iter().zip(o) {
        m.output(&format!("cur_{name}"), s);
    }
    // Observation ports: a node visit (for the order check and statistics) and the stack depth.
    m.output("visit", in_node);
    m.output("visit_node", node);
    m.output("stack_depth", sp);
    m.output("fsm_state", state);
    m
}

/// State names by number, for statistics.
pub const STATE_NAMES: [&str; 7] = ["idle", "aabb", "node", "inner", "leaf", "pop", "done"];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::golden::{Golden, GridRay, Visitor};
    use crate::model::ray::quantize_ray;
    use crate::params::Params;
    use crate::render::camera::Camera;
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
    /// visits and the same triangle stream as `Golden::walk`, ray after ray in one simulation.
    #[test]
    fn visits_what_the_golden_walk_visits_in_its_order() {
        for (name, params) in [("teapot", Params::default()), ("cornell", Params { n: 20, m: 20, ..Params::default() })]
        {
            let scene = Scene::load(&SceneSource::Builtin(name.into()), &params).unwrap();
            let g = Golden::new(&scene);
            let roms = SceneRoms::of(&scene);
            let m = traverse_core(&TraverseParams::new(&roms, 16), &roms);
            let mut sim = Sim::new(&m);
            let cam = Camera::default_for(&scene, 24, 24);
            let mut rays = 0;
            for py in 0..24 {
                for px in 0..24 {
                    let Some(q) = quantize_ray(&scene, &g, &cam.ray(px, py)) else { continue };
                    let mut want = Trace::default();
                    want.max_stack = g.walk(&scene, &q.ray, &mut want).max_stack;
                    let got = run(&m, &mut sim, &q.ray, (py * 24 + px) as u64);
                    assert_eq!(got, want, "{name} pixel {px},{py}");
                    rays += 1;
                }
            }
            assert!(rays > 300, "{rays}");
        }
    }
}
