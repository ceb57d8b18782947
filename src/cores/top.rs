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

use super::brom::{brom, brom2};
use super::closest::{TagLayout, closest_core};
use super::intersect::IntersectParams;
use super::leaf_stream::{Emission, emission, leaf_stream, ray_rams};
use super::ray_port::{BoxExit, RayPort, box_exit, is_unit, ray_port};
use super::traverse::{TraverseParams, traverse_core, word_bits};
use crate::model::golden::GridRay;
use crate::rtl::build::{Builder, Ports, S};
use crate::rtl::width::MAX_WIDTH;
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use crate::scene::rom::Field;
use crate::scene::rom::rom_addr_bits;
use std::rc::Rc;

pub use super::result_queue::RESULT_QUEUE;

/// Ray slots per traversal unit and traversal units, by default (chosen by measurement:
/// docs/CORE.md).
pub const DEFAULT_SLOTS: u32 = 64;
pub const DEFAULT_UNITS: u32 = 2;

#[derive(Clone, Debug)]
pub struct CoreParams {
    pub isect: IntersectParams,
    pub trav: TraverseParams,
    pub tag: TagLayout,
    /// Traversal units feeding the one intersection pipeline.
    pub units: u32,
    /// Clocks of a triangle ROM read (`brom::read_cycles`).
    pub tri_rom_cycles: u32,
}

/// What shapes a core besides its scene: the width of its ray ids, the divider's quotient
/// bits per stage, the clock it is pipelined for, and its ray slots per traversal unit and
/// units. `Default` is `fxrt gen`'s defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoreSpec {
    pub id_width: u32,
    pub div_bits: u32,
    pub target_mhz: u32,
    pub slots: u32,
    pub units: u32,
}

/// The ray id width by default (`--ray-id-width`): a 1024 × 1024 frame's pixel numbers.
pub const DEFAULT_RAY_ID_WIDTH: u32 = 20;

impl Default for CoreSpec {
    fn default() -> CoreSpec {
        CoreSpec {
            id_width: DEFAULT_RAY_ID_WIDTH,
            div_bits: 1,
            target_mhz: super::clock::DEFAULT_TARGET_MHZ,
            slots: DEFAULT_SLOTS,
            units: DEFAULT_UNITS,
        }
    }
}

impl CoreParams {
    /// The default shape but for the ray id width, the divider and the clock target.
    pub fn new(scene: &SceneRoms, id_width: u32, div_bits: u32, target_mhz: u32) -> CoreParams {
        Self::shaped(scene, &CoreSpec { id_width, div_bits, target_mhz, ..CoreSpec::default() })
    }

    /// The core of `shape` for `scene` (not checked: `check` says what the RTL layer cannot
    /// hold).
    pub fn shaped(scene: &SceneRoms, shape: &CoreSpec) -> CoreParams {
        let CoreSpec { id_width, div_bits, target_mhz, slots, units } = *shape;
        let trav = TraverseParams::new(scene, id_width, super::clock::ClockTarget(target_mhz), slots);
        let unit_bits = if units > 1 { rom_addr_bits(units as usize) } else { 0 };
        let tag = TagLayout {
            tri_bits: trav.tri_bits,
            tmin_bits: trav.tmin_width(),
            sp_bits: trav.sp_width(),
            slot_bits: trav.slot_bits() + unit_bits,
        };
        let p = &scene.params;
        let isect = IntersectParams {
            n: p.n,
            m: p.m,
            t: p.t,
            e: scene.edge_shift,
            tag_width: tag.width(),
            div_bits,
            target_mhz,
        };
        CoreParams { isect, trav, tag, units, tri_rom_cycles: super::brom::read_cycles(scene.tri.1.len()) }
    }

    /// Bits of a unit number within a global slot number (0 for one unit).
    pub fn unit_bits(&self) -> u32 {
        self.tag.slot_bits - self.trav.slot_bits()
    }
    /// Global slot numbers of the core (unit bits above slot bits: a power of two per unit).
    pub fn total_slots(&self) -> u32 {
        self.units << self.trav.slot_bits()
    }
    /// Ray slots of the core: the rays it holds at once.
    pub fn slot_count(&self) -> u32 {
        self.units * self.trav.slots
    }

    /// Rejects what the RTL layer cannot hold, naming the parameter to change.
    pub fn check(&self) -> crate::error::Result<()> {
        use crate::error::Error;
        self.isect.check_widths()?;
        let w = self.trav.n + 1 + self.trav.inv_width();
        if w > MAX_WIDTH {
            return Err(Error::param(
                "c",
                format!(
                    "the traversal's plane distance needs n + m + C + 1 = {w} bits; the RTL layer holds {MAX_WIDTH}"
                ),
            ));
        }
        if !(1..=64).contains(&self.trav.slots) {
            return Err(Error::param("slots", format!("{} is out of range: must be 1..=64", self.trav.slots)));
        }
        if !(1..=4).contains(&self.units) {
            return Err(Error::param("units", format!("{} is out of range: must be 1..=4", self.units)));
        }
        // The closest-hit unit keeps a bit per global slot number in one word; a unit's slot
        // numbers take a power of two (3 units × 33 slots are numbered as 3 × 64).
        if self.total_slots() > MAX_WIDTH {
            let numbered = if self.total_slots() == self.slot_count() {
                String::new()
            } else {
                format!(", numbered as {} × {}", self.units, 1u32 << self.trav.slot_bits())
            };
            return Err(crate::error::Error::param(
                "slots",
                format!(
                    "{} units × {} slots = {} ray slots{numbered}; the closest-hit unit holds at most {MAX_WIDTH}: \
                     fewer --slots or --units",
                    self.units,
                    self.trav.slots,
                    self.slot_count()
                ),
            ));
        }
        Ok(())
    }

    /// Rejects a scene whose ROMs do not fit `bram_kbits` of block RAM (each ROM rounded up
    /// to a power-of-two depth, as the printers emit it).
    pub fn check_device(&self, scene: &SceneRoms, bram_kbits: u64) -> crate::error::Result<()> {
        let stack_word = self.trav.n as u64 * 2 + 6 + 32;
        let stack = stack_word
            * crate::scene::rom::rom_depth(self.trav.stack_depth as usize) as u64
            * self.total_slots() as u64;
        let total = scene.rom_bits() + stack;
        if total > bram_kbits * 1024 {
            return Err(crate::error::Error::param(
                "bram-kbits",
                format!(
                    "scene {} needs {} Kb of ROM and stacks, more than the {bram_kbits} Kb of block RAM allowed \
                     (the XC5VLX110T has 5328): use a smaller scene, a smaller --n/--m, fewer --slots/--units, \
                     or raise --bram-kbits for a larger device",
                    scene.name,
                    total.div_ceil(1024)
                ),
            ));
        }
        Ok(())
    }

    /// Cycles from a leaf entry leaving its queue to its result in the closest-hit unit's
    /// accumulator: leaf ROM, triangle ROMs, the pipeline, the unit's input stage.
    pub fn stream_latency(&self) -> u32 {
        1 + self.trav.leaf_rom_cycles
            + self.tri_rom_cycles
            + self.isect.latency()
            + super::closest::input_latency(self.isect.target())
    }
}

/// Consecutive triangle fields grouped into words of at most 128 bits.
pub fn tri_rom_groups(fields: &[Field]) -> Vec<Vec<Field>> {
    let mut groups: Vec<Vec<Field>> = Vec::new();
    for f in fields {
        match groups.last_mut() {
            Some(g) if g.iter().map(|x| x.width).sum::<u32>() + f.width <= MAX_WIDTH => g.push(f.clone()),
            _ => groups.push(vec![f.clone()]),
        }
    }
    groups
}

/// Input ports of the core in order, with types.
pub fn core_inputs(p: &CoreParams) -> Vec<(&'static str, Ty)> {
    let (n, m, iw) = (p.isect.n, p.isect.m, p.trav.inv_width());
    let mut v = vec![("ray_valid", Ty::BIT), ("ray_id", Ty::u(p.trav.id_width))];
    v.extend([("ox", Ty::u(n)), ("oy", Ty::u(n)), ("oz", Ty::u(n))]);
    v.extend([("wx", Ty::s(m)), ("wy", Ty::s(m)), ("wz", Ty::s(m))]);
    v.extend([("invx", Ty::s(iw)), ("invy", Ty::s(iw)), ("invz", Ty::s(iw))]);
    v
}

/// The input values of one ray (valid = 1), in `core_inputs` order.
pub fn ray_inputs(id: u64, ray: &GridRay) -> Vec<i128> {
    let mut v = vec![1, id as i128];
    v.extend(ray.o.iter().map(|&x| x as i128));
    v.extend(ray.w.iter().map(|&x| x as i128));
    v.extend(ray.inv.iter().copied());
    v
}

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
    let port = ray_port(&b, p, &ins);
    let exit = box_exit(&b, p, &port);
    let units = traversal_units(&b, p, scene, &port, &exit);
    b.stage("ray_rams", "the accepted ray into the core's ray RAMs, by global slot");
    let rams = ray_rams(&b, p, &port);
    let leaf = leaf_stream(&b, p, scene, &units.trav, &units.leaf_pop);
    let emitted = emission(&b, p, scene, &leaf, &rams);
    let (done_valid, res, credit_ok) = results(&b, p, &port, &units, &emitted);
    b.output("ray_ready", port.ready);
    b.stage("result_queue", "the results, queued for the consumer (`result_queue.rs`)");
    super::result_queue::result_queue(&b, &res, done_valid, res_ready, credit_ok);
    if debug {
        observe(&b, p, &port, &units.trav, emitted.valid);
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
    /// A leaf merged (closest-hit unit → its unit): valid, global slot, hit, limit, sp.
    merge: [S<'b>; 5],
    /// A slot freed (its result left the core): valid, global slot.
    free: [S<'b>; 2],
    leaf_pop: Vec<S<'b>>,
    done_pop: Vec<S<'b>>,
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
    let merge = [
        wire("merge_valid", bit),
        wire("merge_slot", Ty::u(gb)),
        wire("merge_hit", bit),
        wire("merge_limit", p.trav.dist_ty()),
        wire("merge_sp", Ty::u(p.trav.sp_width())),
    ];
    let free = [wire("free_valid", bit), wire("free_slot", Ty::u(gb))];
    let leaf_pop: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_leaf_pop"), bit)).collect();
    let done_pop: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_done_pop"), bit)).collect();
    let unit = Rc::new(traverse_core(&p.trav, scene));
    let node_words: Vec<S> =
        (0..units).map(|u| b.wire(&format!("u{u}_node_word"), Ty::u(scene.node.0.width))).collect();
    let [merge_valid, merge_slot, merge_hit, merge_limit, merge_sp] = merge;
    let [free_valid, free_slot] = free;
    let trav: Vec<_> = (0..units)
        .map(|u| {
            let we = (port.accept & is_unit(port.slot, u, sb, ub)).name(&format!("u{u}_alloc"));
            let new_valid = (exit.done & is_unit(exit.slot, u, sb, ub)).name(&format!("u{u}_new"));
            let mv = (merge_valid & is_unit(merge_slot, u, sb, ub)).name(&format!("u{u}_merge"));
            let fv = (free_valid & is_unit(free_slot, u, sb, ub)).name(&format!("u{u}_free"));
            let [ox, oy, oz] = port.o;
            let [ix, iy, iz] = port.inv;
            let t = b.instance_named(
                &format!("u_traverse_{u}"),
                &unit,
                &[
                    ("ray_we", we),
                    ("ray_slot", port.unit_slot),
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
                    ("merge_slot", merge_slot.slice(0, sb)),
                    ("merge_hit", merge_hit),
                    ("merge_limit", merge_limit),
                    ("merge_sp", merge_sp),
                    ("free_valid", fv),
                    ("free_slot", free_slot.slice(0, sb)),
                    ("alloc", we),
                    ("leaf_pop", leaf_pop[u as usize]),
                    ("done_pop", done_pop[u as usize]),
                    ("node_word", node_words[u as usize]),
                ],
            );
            b.drive(port.unit_has_free[u as usize], t.get("has_free"));
            b.drive(port.unit_free_slot[u as usize], t.get("free_slot_out"));
            t
        })
        .collect();
    node_roms(b, p, scene, &trav, &node_words);
    Units { trav, merge, free, leaf_pop, done_pop }
}

/// The node ROM: one per two units, on a block RAM's two ports.
fn node_roms<'b>(b: &'b Builder, p: &CoreParams, scene: &SceneRoms, trav: &[Ports<'b>], node_words: &[S<'b>]) {
    let (node_l, node_image) = (&scene.node.0, &scene.node.1);
    let image: Vec<u128> = node_image.iter().map(|w| word_bits(w, 0, node_l.width)).collect();
    let rom_name = format!("node_{}", p.trav.scene_tag);
    for pair in 0..p.units.div_ceil(2) {
        let (u0, u1) = (2 * pair as usize, 2 * pair as usize + 1);
        let (label, nrc) = (format!("u_node_rom_{pair}"), p.trav.node_rom_cycles);
        if u1 < p.units as usize {
            let (a, c) = (trav[u0].get("node_addr"), trav[u1].get("node_addr"));
            let (wa, wc) = brom2(b, &label, &rom_name, node_l.width, image.clone(), a, c, nrc);
            b.drive(node_words[u0], wa);
            b.drive(node_words[u1], wc);
        } else {
            let w = brom(b, &label, &rom_name, node_l.width, image.clone(), trav[u0].get("node_addr"), nrc);
            b.drive(node_words[u0], w);
        }
    }
}

/// Rays done, taken from the units' done queues, lowest unit first (a ray finishes once),
/// while the result queue has room for one more (`res_credit_ok`), and the closest-hit unit
/// that keeps each slot's best hit and unparks slots after their leaves. Returns a ray done
/// (registered), the closest-hit unit's ports and the credit register (`result_queue` drives it).
fn results<'b>(
    b: &'b Builder,
    p: &CoreParams,
    port: &RayPort<'b>,
    units: &Units<'b>,
    emitted: &Emission<'b>,
) -> (S<'b>, Ports<'b>, S<'b>) {
    let (trav, done_pop, ub) = (&units.trav, &units.done_pop, p.unit_bits());
    b.stage("done", "rays done: taken from the units' done queues, lowest unit first, into the closest-hit unit");
    let credit_ok = b.reg("res_credit_ok", Ty::BIT, Some(1));
    let dv: Vec<S> = trav
        .iter()
        .enumerate()
        .map(|(u, t)| {
            let took = b.valid_delay(&format!("u{u}_done_took"), done_pop[u]);
            (t.get("done_valid") & !took & credit_ok).name(&format!("u{u}_done_avail"))
        })
        .collect();
    let mut done_any = dv[0];
    let mut done_slot =
        if ub == 0 { trav[0].get("done_slot") } else { b.cat(&[b.konst(Ty::u(ub), 0), trav[0].get("done_slot")]) };
    b.drive(done_pop[0], dv[0]);
    for u in 1..p.units as usize {
        let mine = (dv[u] & !done_any).name(&format!("u{u}_done_take"));
        b.drive(done_pop[u], mine);
        done_slot = done_any.select(done_slot, b.cat(&[b.konst(Ty::u(ub), u as i128), trav[u].get("done_slot")]));
        done_any = done_any | dv[u];
    }
    let closest =
        Rc::new(closest_core(p.tag, p.total_slots(), p.trav.id_width, p.isect.n, p.isect.m, p.isect.target()));
    let mut cin: Vec<S> = emitted.pipe.all().to_vec();
    // Registered before the closest-hit unit, whose per-slot selects it drives (the units'
    // queues sit across the die).
    let (done_any, done_slot) = (b.valid_delay("done_valid_r", done_any), b.delay("done_slot_r", done_slot));
    cin.extend([port.accept, port.slot, port.id, done_any, done_slot]);
    let res = b.instance("u_closest", &closest, &cin);
    let names = ["merge_valid", "merge_slot", "merge_hit", "merge_limit", "merge_sp", "free_valid", "free_slot"];
    for (wire, name) in units.merge.iter().chain(&units.free).zip(names) {
        b.drive(*wire, res.get(name));
    }
    (done_any, res, credit_ok)
}

/// Observation ports for `fxrt sim`: a triangle entering the pipeline, the deepest stack in
/// the units' N stages, node visits and culls this clock, slots holding a ray. The deepest
/// stack and the occupied slots come through a tree with a register after each level (a
/// clock per level of log2 U: a frame's maximum and sums hardly notice), so these counters
/// are never the core's slowest path (four units' chained maxima were: 102.5 MHz).
fn observe<'b>(b: &'b Builder, p: &CoreParams, port: &RayPort<'b>, trav: &[Ports<'b>], busy: S<'b>) {
    b.stage("observe", "observation ports for fxrt sim: pipeline busy, stack depth, visits, culls, slots, walks");
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
    b.output("visits", sum("visit", 3).name("visits_c"));
    b.output("culls", sum("cull", 3).name("culls_c"));
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
    }
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
