//! The whole ray tracing core for one scene: ray stream in, closest hits out (in the order
//! rays finish, tagged with the ray id).
//!
//! ```text
//! ray_valid/ready, id, o, ω, 1/ω ─► box exit ─► U traversal units (K ray slots each) ─► leaf queues
//!      ┌──────────────────────────────────────────────── merge (unpark, cull limit) ◄─┐   │ arbiter
//!      ▼                                                                              │   ▼
//!  traversal units ── done queues ─► closest hit ─► res_*     leaf ROM ─► triangle ROMs ─► intersection pipeline
//! ```
//!
//! A ray is accepted when the box-exit unit is free (one ray per 4 clocks: it issues the three
//! exit distances of the scene box to a plane unit of its own) and the unit whose turn it is
//! has a free slot; the ray's origin and reciprocal direction go into that unit's ray RAMs, its
//! origin and direction into the core's ray RAMs (read for the intersection pipeline) and its
//! id into the closest-hit unit's; the box exit follows through the unit's new-ray queue.
//! The leaf stream takes whole leaves from the units' leaf queues in turn and sends one
//! triangle per clock, tagged with the ray's slot, into the pipeline; the closest-hit unit keeps
//! each slot's best hit and unparks the slot after each leaf (`closest.rs`).
//! The triangle table is wider than a signal may be (5 + 3n + 6m bits), so it is split into
//! ROMs of whole fields, ≤ 128 bits each, all read at the same address.

use super::brom::rom_reads;
use super::leaf_stream::{Emission, emission, leaf_stream, ray_rams};
use super::ray_port::{BoxExit, RayPort, box_exit, is_unit, ray_port};
use super::top_memory::{MemoryObserved, NodeIn, memory_inputs, memory_side};
use super::traverse::{traverse_core, word_bits};
use crate::rtl::build::{Builder, Ports, S};
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use std::rc::Rc;

pub use super::core_params::{
    CoreParams, CoreSpec, DEFAULT_RAY_ID_WIDTH, DEFAULT_SLOTS, DEFAULT_UNITS, core_inputs, ray_inputs, tri_rom_groups,
};
pub use super::result_queue::RESULT_QUEUE;

/// The core with its observation ports (`verify::frame::OBSERVED`, the visit ports): what the
/// simulations count with.
pub fn core_module(p: &CoreParams, scene: &SceneRoms) -> Module {
    core_module_with(p, scene, true)
}

/// The core; with `debug` its observation ports too (busy, stack_depth, visits, culls,
/// occupied, accept, accept_id, accept_slot, visit{u}, visit{u}_slot, visit{u}_node), which
/// integrators do not need (`fxrt gen --debug-ports`). Built stage by stage, in the order the
/// diagram above reads; each stage is a block of the printed HDL.
pub fn core_module_with(p: &CoreParams, scene: &SceneRoms, debug: bool) -> Module {
    let b = Builder::new(&format!("fxrt_core_{}", p.trav.scene_tag));
    let ins: Vec<S> = core_inputs(p).iter().map(|(name, ty)| b.input(name, *ty)).collect();
    let res_ready = b.input("res_ready", Ty::BIT);
    let mem_in: Option<Vec<S>> =
        p.mem.as_ref().map(|m| memory_inputs(m).iter().map(|(name, ty)| b.input(name, *ty)).collect());
    let port = ray_port(&b, p, &ins);
    let exit = box_exit(&b, p, &port);
    let units = traversal_units(&b, p, scene, &port, &exit);
    b.stage("ray_rams", "the accepted ray into the core's ray RAMs, by global slot");
    let rams: Vec<_> = (0..p.pipelines).map(|lane| ray_rams(&b, p, &port, lane)).collect();
    let (emitted, mem_observed) = match (&p.mem, &mem_in) {
        (Some(m), Some(inputs)) => {
            let (e, o) = memory_side(&b, p, m, inputs, &units.trav, &units.node_in, &units.leaf_pop, &rams[0]);
            (vec![e], Some(o))
        }
        _ => {
            let lu = p.lane_units() as usize;
            let leaves: Vec<_> = (0..p.pipelines as usize)
                .map(|l| {
                    let (trav, pops) = (&units.trav[l * lu..(l + 1) * lu], &units.leaf_pop[l * lu..(l + 1) * lu]);
                    leaf_stream(&b, p, l as u32, scene, trav, pops)
                })
                .collect();
            (emission(&b, p, scene, &leaves, &rams), None)
        }
    };
    let (done_valid, lanes, credit_ok) = results(&b, p, &port, &units, &emitted);
    b.output("ray_ready", port.ready);
    b.stage("result_queue", "the results, queued for the consumer (`result_queue.rs`)");
    let field = |name: &str| result_field(&lanes, name);
    super::result_queue::result_queue(&b, &field, done_valid, res_ready, credit_ok);
    if debug {
        observe(&b, p, &port, &units.trav, &emitted);
        if let Some(o) = mem_observed {
            observe_memory(&b, &o);
        }
    }
    b.end_stage();
    let mut m = b.finish();
    m.std_ports = true;
    m
}

/// The traversal units and their node ROMs: the units' ports, and the wires into them the
/// closest-hit unit and the leaf stream drive.
struct Units<'b> {
    trav: Vec<Ports<'b>>,
    /// A leaf merged (closest-hit unit → its unit): per unit valid, slot in the unit, hit.
    merge_unit: Vec<[S<'b>; 3]>,
    /// … and per lane, for its units, the limit and sp.
    merge: Vec<[S<'b>; 2]>,
    /// Per lane, a slot freed (its result left the core): valid, slot within the lane.
    free: Vec<[S<'b>; 2]>,
    leaf_pop: Vec<S<'b>>,
    done_pop: Vec<S<'b>>,
    /// With external memory: what each unit's node cache drives into it.
    node_in: Vec<NodeIn<'b>>,
}

fn traversal_units<'b>(
    b: &'b Builder,
    p: &CoreParams,
    scene: &SceneRoms,
    port: &RayPort<'b>,
    exit: &BoxExit<'b>,
) -> Units<'b> {
    let (units, sb, ub, gb, bit) = (p.units, p.trav.slot_bits(), p.unit_bits(), p.tag.slot_bits, Ty::BIT);
    b.stage("units", "the traversal units (K ray slots each) and their node ROMs, one per two units");
    let wire = |name: &str, ty: Ty| b.wire(name, ty);
    let merge_unit: Vec<[S; 3]> = (0..units)
        .map(|u| {
            let w = |name: &str, ty: Ty| wire(&format!("u{u}_merge_{name}"), ty);
            [w("valid", bit), w("slot", Ty::u(sb)), w("hit", bit)]
        })
        .collect();
    let (lanes, lu, lb) = (p.pipelines, p.lane_units(), p.lane_bits());
    let lane_wire = |l: u32, name: &str, ty: Ty| wire(&p.lane_name(l, name), ty);
    let merge: Vec<[S; 2]> = (0..lanes)
        .map(|l| [lane_wire(l, "merge_limit", p.trav.dist_ty()), lane_wire(l, "merge_sp", Ty::u(p.trav.sp_width()))])
        .collect();
    let free: Vec<[S; 2]> =
        (0..lanes).map(|l| [lane_wire(l, "free_valid", bit), lane_wire(l, "free_slot", Ty::u(gb - lb))]).collect();
    let leaf_pop: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_leaf_pop"), bit)).collect();
    let done_pop: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_done_pop"), bit)).collect();
    let unit = Rc::new(traverse_core(&p.trav));
    let node_words: Vec<S> =
        (0..units).map(|u| b.wire(&format!("u{u}_node_word"), Ty::u(p.trav.node_layout.width))).collect();
    let pair_width = 2 * p.trav.leaf_fields_bits();
    let pair_words: Vec<S> = match p.trav.pair_rom_cycles {
        Some(_) => (0..units).map(|u| b.wire(&format!("u{u}_pair_word"), Ty::u(pair_width))).collect(),
        None => Vec::new(),
    };
    // With external memory, the node cache's answer besides the word (hit, wait, done).
    let node_in: Vec<NodeIn> = match &p.mem {
        Some(_) => (0..units)
            .map(|u| {
                let w = |name: &str, ty: Ty| b.wire(&format!("u{u}_node_{name}"), ty);
                let seq = Ty::u(super::cache::SEQ_BITS);
                [node_words[u as usize], w("hit", bit), w("wait", seq), w("done", seq)]
            })
            .collect(),
        None => Vec::new(),
    };
    let trav: Vec<_> = (0..units)
        .map(|u| {
            let [merge_limit, merge_sp] = merge[(u / lu) as usize];
            let [free_valid, free_slot] = free[(u / lu) as usize];
            let new_valid = (exit.done & is_unit(exit.slot, u, sb, ub)).name(&format!("u{u}_new"));
            let [mv, merge_slot, merge_hit] = merge_unit[u as usize];
            let fv = (free_valid & is_unit(free_slot, u % lu, sb, ub - lb)).name(&format!("u{u}_free"));
            let [ox, oy, oz] = port.o;
            let [ix, iy, iz] = port.inv;
            let (wes, slots) = (&port.unit_we[u as usize], &port.unit_slot[u as usize]);
            let names: Vec<[String; 2]> =
                (0..slots.len()).map(|g| [format!("ray_we_g{g}"), format!("ray_slot_g{g}")]).collect();
            let mut ins: Vec<(&str, S)> = names
                .iter()
                .zip(wes.iter().zip(slots))
                .flat_map(|([we_name, slot_name], (&we, &slot))| [(we_name.as_str(), we), (slot_name.as_str(), slot)])
                .collect();
            ins.extend([
                ("ox", ox),
                ("oy", oy),
                ("oz", oz),
                ("invx", ix),
                ("invy", iy),
                ("invz", iz),
                ("new_valid", new_valid),
                ("new_slot", exit.slot.slice(0, sb)),
                ("new_tmax", exit.tmax),
                ("new_miss", exit.miss),
                ("merge_valid", mv),
                ("merge_slot", merge_slot),
                ("merge_hit", merge_hit),
                ("merge_limit", merge_limit),
                ("merge_sp", merge_sp),
                ("free_valid", fv),
                ("free_slot", free_slot.slice(0, sb)),
                ("alloc", wes[slots.len()]),
                ("leaf_pop", leaf_pop[u as usize]),
                ("done_pop", done_pop[u as usize]),
                ("node_word", node_words[u as usize]),
            ]);
            if let Some([_, hit, wait, done]) = node_in.get(u as usize) {
                ins.extend([("node_hit", *hit), ("node_wait", *wait), ("node_done", *done)]);
            }
            if let Some(&word) = pair_words.get(u as usize) {
                ins.push(("pair_word", word));
            }
            let t = b.instance_named(&format!("u_traverse_{u}"), &unit, &ins);
            b.drive(port.unit_has_free[u as usize], t.get("has_free"));
            b.drive(port.unit_free_slot[u as usize], t.get("free_slot_out"));
            t
        })
        .collect();
    if p.mem.is_none() {
        node_roms(b, p, scene, &trav, &node_words);
    }
    if let Some(cycles) = p.trav.pair_rom_cycles {
        // The pair ROM (DECISIONS 137): one per two units, as the node ROM.
        let image =
            crate::cores::traverse::pair_image(scene).expect("a unit sends leaves only where the pair image is");
        let addrs: Vec<S> = trav.iter().map(|t| t.get("pair_addr")).collect();
        let label = |pair: usize| format!("u_pair_rom_{pair}");
        let rom_name = format!("pair_{}", p.trav.scene_tag);
        let words = rom_reads(b, &label, &rom_name, pair_width, &image, &addrs, cycles);
        for (wire, word) in pair_words.iter().zip(words) {
            b.drive(*wire, word);
        }
    }
    Units { trav, merge_unit, merge, free, leaf_pop, done_pop, node_in }
}

/// The node ROM: one per two units, on a block RAM's two ports.
fn node_roms<'b>(b: &'b Builder, p: &CoreParams, scene: &SceneRoms, trav: &[Ports<'b>], node_words: &[S<'b>]) {
    let (node_l, node_image) = (&scene.node.0, &scene.node.1);
    let image: Vec<u128> = node_image.iter().map(|w| word_bits(w, 0, node_l.width)).collect();
    let addrs: Vec<S> = trav.iter().map(|t| t.get("node_addr")).collect();
    let label = |pair: usize| format!("u_node_rom_{pair}");
    let rom_name = format!("node_{}", p.trav.scene_tag);
    let words = rom_reads(b, &label, &rom_name, node_l.width, &image, &addrs, p.trav.node_rom_cycles);
    for (wire, word) in node_words.iter().zip(words) {
        b.drive(*wire, word);
    }
}

/// Rays done, taken from the units' done queues, lowest unit first (a ray finishes once),
/// while the result queue has room for one more (`res_credit_ok`), and the closest-hit units
/// (one per lane) that keep each slot's best hit and unpark slots after their leaves. Returns
/// a ray done (registered), the closest-hit units' ports and the credit register
/// (`result_queue` drives it).
fn results<'b>(
    b: &'b Builder,
    p: &CoreParams,
    port: &RayPort<'b>,
    units: &Units<'b>,
    emitted: &[Emission<'b>],
) -> (S<'b>, Vec<Ports<'b>>, S<'b>) {
    let (trav, done_pop, ub) = (&units.trav, &units.done_pop, p.unit_bits());
    b.stage("done", "rays done: taken from the units' done queues, lowest unit first, into the closest-hit unit");
    let credit_ok = b.reg("res_credit_ok", Ty::BIT, Some(1));
    // A spread core picks the unit without the credit and gates only the pops and the valid
    // with it: the credit through the pick's chain into `done_slot_r` was 6.91 ns at a seed.
    let spread = p.isect.spread;
    let dv: Vec<S> = trav
        .iter()
        .enumerate()
        .map(|(u, t)| {
            let took = b.valid_delay(&format!("u{u}_done_took"), done_pop[u]);
            let avail = t.get("done_valid") & !took;
            if spread { avail } else { avail & credit_ok }.name(&format!("u{u}_done_avail"))
        })
        .collect();
    let gated = |x: S<'b>| if spread { x & credit_ok } else { x };
    let mut done_any = dv[0];
    let mut done_slot =
        if ub == 0 { trav[0].get("done_slot") } else { b.cat(&[b.konst(Ty::u(ub), 0), trav[0].get("done_slot")]) };
    b.drive(done_pop[0], gated(dv[0]));
    for u in 1..p.units as usize {
        let mine = gated(dv[u] & !done_any).name(&format!("u{u}_done_take"));
        b.drive(done_pop[u], mine);
        done_slot = done_any.select(done_slot, b.cat(&[b.konst(Ty::u(ub), u as i128), trav[u].get("done_slot")]));
        done_any = done_any | dv[u];
    }
    let done_any = gated(done_any);
    let closest = Rc::new(p.closest_module());
    // Registered by the arbiter (the units' queues sit across the die). A spread core
    // registers it again before the closest-hit units, whose per-slot selects the second
    // register's copies drive: with the copies loaded from the arbiter's select, the four-unit
    // core's slowest paths at a placement seed were a unit's queue flag through the select
    // into them (8.16 ns, 17 registers loaded from one LUT). The credits count the first
    // (`popped`): a result then reaches the queue a clock after it is counted, never before.
    let (picked, picked_slot) = (b.valid_delay("done_valid_r", done_any), b.delay("done_slot_r", done_slot));
    let (done_any, done_slot) = if p.isect.spread {
        (b.valid_delay("done_valid_r2", picked), b.delay("done_slot_r2", picked_slot))
    } else {
        (picked, picked_slot)
    };
    let (lb, lsb, lu) = (p.lane_bits(), p.lane_slot_bits(), p.lane_units() as usize);
    // A copy of the slot per group of 16 has-best bits in each lane's unit (`slot_bit_2`).
    let groups = super::slot_bit_groups(p.total_slots() >> lb) as usize;
    let done_copies = b.copies(done_slot, groups * emitted.len());
    let outs: Vec<Ports> = emitted
        .iter()
        .enumerate()
        .map(|(lane, e)| {
            let mut cin: Vec<S> = e.pipe.all().to_vec();
            if lb == 0 {
                let copies: Vec<S> = done_copies.iter().rev().copied().collect();
                cin.extend([port.accept, port.closest_slot, port.id, done_any, done_slot, b.cat(&copies)]);
            } else {
                // The lane's own slots: the global slot's top bits are the lane.
                let nm = |x: &str| p.lane_name(lane as u32, x);
                let mine = |slot: S<'b>| p.in_lane(slot, lane as u32);
                let id_we = (port.accept & mine(port.closest_slot)).name(&nm("id_we"));
                let done = (done_any & mine(done_slot)).name(&nm("done_valid"));
                let copies: Vec<S> =
                    done_copies[lane * groups..][..groups].iter().rev().map(|c| c.slice(0, lsb)).collect();
                cin.extend([
                    id_we,
                    port.closest_slot.slice(0, lsb),
                    port.id,
                    done,
                    done_slot.slice(0, lsb),
                    b.cat(&copies),
                ]);
            }
            b.instance(&p.lane_name(lane as u32, "u_closest"), &closest, &cin)
        })
        .collect();
    for (u, wires) in units.merge_unit.iter().enumerate() {
        for (wire, name) in wires.iter().zip(["valid", "slot", "hit"]) {
            b.drive(*wire, outs[u / lu].get(&format!("merge_{name}{}", u % lu)));
        }
    }
    let names = ["merge_limit", "merge_sp", "free_valid", "free_slot"];
    for (lane, res) in outs.iter().enumerate() {
        for (wire, name) in units.merge[lane].iter().chain(&units.free[lane]).zip(names) {
            b.drive(*wire, res.get(name));
        }
    }
    (picked, outs, credit_ok)
}

/// Result field `res_{name}` of the closest-hit units: a lane's shows a result three clocks
/// after its done input, and rays finish one a clock, so at most one lane shows one in a clock
/// (`valid` is their OR, a field the showing lane's).
fn result_field<'b>(lanes: &[Ports<'b>], name: &str) -> S<'b> {
    let get = |r: &Ports<'b>, f: &str| r.get(&format!("res_{f}"));
    let (first, rest) = lanes.split_first().expect("a lane");
    let mut x = get(first, name);
    for r in rest {
        x = if name == "valid" { x | get(r, name) } else { get(r, "valid").select(get(r, name), x) };
    }
    if rest.is_empty() { x } else { x.name(&format!("res_{name}_lanes")) }
}

/// Observation ports for `fxrt sim`: a triangle entering the pipeline, the deepest stack in
/// the units' N stages, node visits and culls this clock, slots holding a ray. The deepest
/// stack and the occupied slots come through a tree with a register after each level (a
/// clock per level of log2 U: a frame's maximum and sums hardly notice), so these counters
/// are never the core's slowest path (four units' chained maxima were: 102.5 MHz).
fn observe<'b>(b: &'b Builder, p: &CoreParams, port: &RayPort<'b>, trav: &[Ports<'b>], emitted: &[Emission<'b>]) {
    b.stage("observe", "observation ports for fxrt sim: pipeline busy, stack depth, visits, culls, slots, walks");
    // Triangles entering the pipelines this clock (one bit with one pipeline).
    let busy = match emitted {
        [one] => one.valid,
        _ => {
            let w = 32 - (emitted.len() as u32).leading_zeros();
            emitted.iter().map(|e| e.valid.resize(w)).reduce(|a, c| a + c).expect("a lane").name("busy_c")
        }
    };
    b.output("busy", busy);
    let sum = |port: &str, w: u32| trav.iter().map(|t| t.get(port).resize(w)).reduce(|a, c| a + c).expect("a unit");
    fn tree<'b>(b: &'b Builder, name: &str, mut level: Vec<S<'b>>, join: impl Fn(S<'b>, S<'b>) -> S<'b>) -> S<'b> {
        let mut depth = 0;
        while level.len() > 1 {
            depth += 1;
            let next: Vec<S<'b>> =
                level.chunks(2).map(|p| if p.len() == 2 { join(p[0], p[1]) } else { p[0] }).collect();
            level = next.into_iter().enumerate().map(|(i, x)| b.delay(&format!("{name}_l{depth}_{i}"), x)).collect();
        }
        level[0]
    }
    let depths = trav.iter().map(|t| t.get("depth")).collect();
    b.output("stack_depth", tree(b, "obs_depth", depths, |a, c| a.max(c)));
    // At most one visit or cull per unit and clock (two visits where a parent sends its leaf
    // child: one in N, one in G); 3 bits at least, as for four units.
    let sends = p.trav.pair_rom_cycles.is_some();
    let count_bits = (32 - (p.units << sends as u32).leading_zeros()).max(3);
    let visit_ports: &[&str] = if sends { &["visit", "sent"] } else { &["visit"] };
    let visits = visit_ports.iter().map(|port| sum(port, count_bits)).reduce(|a, c| a + c).expect("a port");
    b.output("visits", visits.name("visits_c"));
    b.output("culls", sum("cull", count_bits).name("culls_c"));
    let occupied = trav.iter().map(|t| t.get("occupied").resize(p.tag.slot_bits + 1)).collect();
    b.output("occupied", tree(b, "obs_occupied", occupied, |a, c| a + c));
    // The walk of every slot (for the visit-order check): the ray written into a slot, and each
    // unit's node visits.
    b.output("accept", port.accept);
    b.output("accept_id", port.id);
    b.output("accept_slot", port.slot);
    for (u, t) in trav.iter().enumerate() {
        b.output(&format!("visit{u}"), t.get("visit"));
        b.output(&format!("visit{u}_slot"), t.get("visit_slot"));
        b.output(&format!("visit{u}_node"), t.get("visit_node"));
        if sends {
            b.output(&format!("sent{u}"), t.get("sent"));
            b.output(&format!("sent{u}_slot"), t.get("sent_slot"));
            b.output(&format!("sent{u}_node"), t.get("sent_node"));
        }
    }
}

/// With external memory, observation ports for `fxrt sim`: node lookups answered and hits,
/// triangle lookups answered and hits, a beat in, and a clock the pipeline took no triangle while
/// a leaf waited for memory.
fn observe_memory<'b>(b: &'b Builder, o: &MemoryObserved<'b>) {
    b.output("node_looks", o.node_looks);
    b.output("node_hits", o.node_hits);
    b.output("tri_looks", o.tri.looks);
    b.output("tri_hits", o.tri.hits);
    b.output("mem_beat", o.beat);
    b.output("mem_stall", o.tri.stall);
}

/// The core fed by the on-chip ray generator instead of the ray port (the thesis's demo):
/// no inputs but the clock and reset; the same result outputs as `core` (`core_module_with`,
/// observation outputs included when it has them), every result taken the clock it is shown.
pub fn core_with_raygen(p: &CoreParams, core: &Rc<Module>, g: &crate::model::raygen::RayGen) -> Module {
    let mut m = Module::new(&format!("fxrt_core_raygen_{}", p.trav.scene_tag));
    m.std_ports = true;
    let generator = Rc::new(super::raygen::raygen_core(g, p.isect.n, p.isect.m, p.trav.c, p.trav.id_width));
    let ready = m.wire("ready", Ty::BIT);
    let rays = m.instance("u_raygen", &generator, &[ready]);
    // Results are taken the clock they are shown.
    let mut ins = rays;
    ins.push(m.konst("res_ready", Ty::BIT, 1));
    let outs = m.instance("u_core", core, &ins);
    for (k, (name, _)) in core.outputs.iter().enumerate() {
        if name == "ray_ready" {
            m.drive(ready, outs[k]);
        } else {
            m.output(name, outs[k]);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::rtl::netlist::Def;
    use crate::scene::{Scene, SceneSource};

    /// Registers of `m` whose names start with `prefix`, with what each loads.
    fn regs<'m>(m: &'m Module, prefix: &str) -> Vec<(&'m str, &'m str)> {
        m.signals
            .iter()
            .filter_map(|s| match s.def {
                Def::Reg { next: Some(next), .. } if s.name.starts_with(prefix) => {
                    Some((s.name.as_str(), m.signals[next.0 as usize].name.as_str()))
                }
                _ => None,
            })
            .collect()
    }

    /// A spread core (four units, `clock::spread`) copies the done slot from a register, not
    /// from the arbiter's select, copies the has-best bit per result field and lands its plane
    /// products in fabric registers; the two-unit default has none of these (its netlist is
    /// the one measured: generated/measured).
    #[test]
    fn a_spread_core_registers_its_cross_die_values_and_the_default_does_not() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        let shape = |units, pipelines| CoreParams::shaped(&roms, &CoreSpec { units, pipelines, ..CoreSpec::default() });
        for (units, pipelines, spread) in [(4, 2, true), (2, 1, false)] {
            let p = shape(units, pipelines);
            let top = core_module(&p, &roms);
            let copies = regs(&top, "done_slot_r2");
            if spread {
                assert!(copies.len() > 1, "{units} units: {copies:?}");
                for (name, loads) in &copies {
                    assert_eq!(*loads, "done_slot_r", "{name} loads the arbiter's register");
                }
            } else {
                assert!(copies.is_empty(), "{copies:?}");
            }
            let hierarchy = top.hierarchy();
            let closest = hierarchy.iter().find(|m| m.name.starts_with("fxrt_closest")).unwrap();
            assert_eq!(regs(closest, "d1_has").len(), if spread { 5 } else { 1 }, "{}", closest.name);
            let plane = hierarchy.iter().filter(|m| m.name.starts_with("fxrt_mul")).map(|m| m.name.as_str());
            let landed: Vec<&str> = plane.filter(|n| n.contains("_d4")).collect();
            assert_eq!(landed.is_empty(), !spread, "{units} units: {landed:?}");
            assert_eq!(p.trav.product.dsp_regs, if spread { 4 } else { 3 });
            // The intersection pipelines' products land too, and the closest-hit compare is cut.
            assert_eq!(p.isect.mul_style().dsp_regs, if spread { 4 } else { 3 });
            let pipes: Vec<&str> =
                hierarchy.iter().filter(|m| m.name.starts_with("fxrt_intersect")).map(|m| m.name.as_str()).collect();
            assert!(!pipes.is_empty() && pipes.iter().all(|n| n.ends_with("_sp") == spread), "{pipes:?}");
            assert_eq!(regs(closest, "m2_tt_hi_less").len(), spread as usize, "{}", closest.name);
            // Its units send their near leaves from the parent's step, from a pair ROM per two
            // units (DECISIONS 137).
            let pair_roms = top.instances.iter().filter(|i| i.module.name.starts_with("fxrt_brom_pair_")).count();
            assert_eq!(pair_roms, if spread { units as usize / 2 } else { 0 });
            assert_eq!(top.outputs.iter().any(|o| o.0 == "sent0"), spread);
        }
    }
}
