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
use super::intersect::{IntersectParams, intersect_core};
use super::lt_chain;
use super::plane::{PlaneIssue, plane_unit};
use super::traverse::{TraverseParams, field, traverse_core, word_bits};
use crate::model::golden::GridRay;
use crate::rtl::build::{Builder, S};
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

impl CoreParams {
    pub fn new(scene: &SceneRoms, id_width: u32, div_bits: u32, target_mhz: u32) -> CoreParams {
        Self::with_slots(scene, id_width, div_bits, target_mhz, DEFAULT_SLOTS, DEFAULT_UNITS)
    }

    pub fn with_slots(
        scene: &SceneRoms,
        id_width: u32,
        div_bits: u32,
        target_mhz: u32,
        slots: u32,
        units: u32,
    ) -> CoreParams {
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

/// The core with its observation ports (`flow::frame::OBSERVED`, the visit ports): what the
/// simulations count with.
pub fn core_module(p: &CoreParams, scene: &SceneRoms) -> Module {
    core_module_with(p, scene, true)
}

/// The core; with `debug` its observation ports too (busy, stack_depth, visits, culls,
/// occupied, accept, accept_id, accept_slot, visit{u}, visit{u}_slot, visit{u}_node), which
/// integrators do not need (`fxrt gen --debug-ports`).
pub fn core_module_with(p: &CoreParams, scene: &SceneRoms, debug: bool) -> Module {
    let scene_tag = &p.trav.scene_tag;
    let b = Builder::new(&format!("fxrt_core_{scene_tag}"));
    let ins: Vec<S> = core_inputs(p).iter().map(|(name, ty)| b.input(name, *ty)).collect();
    let [ray_valid, ray_id, ox, oy, oz, wx, wy, wz, ix, iy, iz] = ins[..] else { unreachable!("11 ray ports") };
    let res_ready = b.input("res_ready", Ty::BIT);
    let (n, units, sb, gb) = (p.isect.n, p.units, p.trav.slot_bits(), p.tag.slot_bits);
    let ub = p.unit_bits();
    let bit = Ty::BIT;
    fn is_unit(slot: S<'_>, u: u32, sb: u32, ub: u32) -> S<'_> {
        if ub == 0 { slot.k(0).resize(1).eq(0) } else { slot.slice(sb, ub).eq(u as i128) }
    }

    // Wires from the units (driven once they are instantiated).
    let has_free_w: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_has_free"), bit)).collect();
    let free_idx_w: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_free_slot"), Ty::u(sb))).collect();

    // Acceptance: the box-exit unit takes a ray every 4 clocks (it issues three distances and
    // its plane unit reads the ray one clock after the last issue), into the unit whose turn it
    // is (`turn` moves on with every ray and every clock that unit is full).
    let turn = b.reg("turn", Ty::u(ub.max(1)), Some(0));
    let phase = b.reg("box_phase", Ty::u(2), Some(0));
    // The units' free-slot outputs in registers of the top's own (the units sit across the die):
    // a clock staler still, which the 4-clock cadence covers (a unit masks a slot it gave for a
    // clock, and the next ray comes 4 clocks later).
    // Reset as the units' registers are (all free, slot 0), so idling after reset changes nothing.
    let copy = |name: String, x: S<'_>, reset: i128| {
        let r = b.reg(&name, x.ty(), Some(reset));
        b.next(r, x);
        r
    };
    let free_idx: Vec<S> =
        free_idx_w.iter().enumerate().map(|(u, &x)| copy(format!("u{u}_free_slot_r"), x, 0)).collect();
    // Whether the unit whose turn it is has a free slot, as one register: chosen by the next
    // turn among the units' outputs (what copies of them would hold next clock), it equals the
    // choice by `turn` among such copies, so the take — which loads every port register, a net
    // across the die — depends on three registers through one LUT (with four units the choice
    // after the copies cost 9.6 ns: 103.8 MHz).
    let turn_free = b.reg("turn_free", bit, Some(1));
    let turn_slot = if units == 1 {
        free_idx[0]
    } else {
        b.case(turn, &(0..units).map(|u| (u as u128, free_idx[u as usize])).collect::<Vec<_>>(), free_idx[0])
    };
    // The ray port's register: a ray waits in it for the box-exit unit and a slot. The port is
    // ready when the register is empty or its ray is taken this clock (no path from ray_valid
    // to ray_ready); the register loads whenever the port is ready.
    let in_valid = b.reg("in_valid", bit, Some(0));
    let take = (in_valid & phase.eq(0) & turn_free).name("take");
    let port_ready = (!in_valid | take).name("port_ready");
    b.next(in_valid, ray_valid | (in_valid & !take));
    let hold = |s: S| {
        let r = b.reg(&format!("in_{}", b.name_of(s.sig)), s.ty(), None);
        b.next_when(r, port_ready, s);
        r
    };
    let [in_id, ox, oy, oz, wx, wy, wz, ix, iy, iz] = [ray_id, ox, oy, oz, wx, wy, wz, ix, iy, iz].map(hold);
    let take_slot = if ub == 0 { turn_slot } else { b.cat(&[turn.resize(ub), turn_slot]) }.name("take_slot");
    let next_turn = (turn + 1).name("turn_plus_1");
    let next_turn =
        if units.is_power_of_two() { next_turn } else { next_turn.eq(units as i128).select(turn.k(0), next_turn) };
    let turn_next = (take | !turn_free).select(next_turn, turn).name("turn_next");
    b.next(turn, turn_next);
    let pick = |u: u32| (u as u128, has_free_w[u as usize]);
    b.next(
        turn_free,
        if units == 1 {
            has_free_w[0]
        } else {
            b.case(turn_next, &(0..units).map(pick).collect::<Vec<_>>(), b.konst(bit, 0))
        },
    );
    b.next(phase, (take | phase.ne(0)).select(phase + 1, phase));
    // The box-exit unit's operands load whenever it is idle: when a ray is taken they hold it.
    let idle = phase.eq(0).name("box_idle");
    let box_reg = |s: S| {
        let r = b.reg(&format!("box_{}", b.name_of(s.sig)), s.ty(), None);
        b.next_when(r, idle, s);
        r
    };
    let bo = [ox, oy, oz].map(box_reg);
    let binv = [ix, iy, iz].map(box_reg);
    // The taken ray is written into the slot's RAMs a clock later, from registers of its own:
    // `accept` drives the write enables of every ray RAM and the units' free bits, far across
    // the die, so it leaves a register rather than the take decision's logic. The slot still
    // reads as taken at the next take (4 clocks later at the earliest): the unit sees `alloc` a
    // clock after the take and masks its free output the clock after (`just_alloc`), which the
    // top's copies show 3 clocks after the take; a clock after that they show the new lowest
    // free slot. (One clock more would still be safe, two would give a slot twice: the
    // visit-order test fails then.)
    let accept = b.valid_delay("accept", take);
    let gslot = b.delay("accept_slot", take_slot);
    let [ray_id, ox, oy, oz, wx, wy, wz, ix, iy, iz] =
        [in_id, ox, oy, oz, wx, wy, wz, ix, iy, iz].map(|s| b.delay(&format!("acc_{}", b.name_of(s.sig)), s));
    let turn_slot = gslot.slice(0, sb);

    let box_slot = b.reg("box_slot", Ty::u(gb), None);
    b.next_when(box_slot, take, take_slot);
    let axis = (phase - 1).name("box_axis");
    let hi = [0, 1, 2].map(|k| b.konst_named(&format!("box_hi_{k}"), Ty::u(n), p.trav.box_hi[k] as i128));
    let neg = b.pick(axis, binv).msb().name("box_neg");
    let issue = PlaneIssue {
        valid: phase.ne(0).name("box_issue"),
        last: phase.eq(3).name("box_issue_last"),
        plane: neg.select(hi[0].k(0), b.pick(axis, hi)).name("box_plane"),
        axis,
    };
    let pu = plane_unit(&b, n, p.trav.c, bo, binv, issue, p.trav.product);
    let plane_t = pu.t;
    let box_d1 = b.delay("box_d1", plane_t);
    let box_d2 = b.delay("box_d2", box_d1);
    let box_d3 = b.delay("box_d3", box_d2);
    let box_lt1 = b.delay("box_lt1", lt_chain(plane_t, box_d1).name("box_lt1_c"));
    let box_lt2 = b.delay("box_lt2", lt_chain(plane_t, box_d2).name("box_lt2_c"));
    let box_lt1_d = b.delay("box_lt1_d", box_lt1);
    let box_tmax = (box_lt1 & box_lt2).select(box_d1, box_lt1_d.select(box_d2, box_d3)).name("box_tmax");
    let box_miss = (box_d1.msb() | box_d2.msb() | box_d3.msb()).name("box_miss");
    let box_done = b.valid_delay("box_done", (pu.valid & pu.last).name("box_last"));
    let box_done_slot = b.delay_line("box_done_slot", box_slot, pu.latency + 1);

    // The traversal units.
    let wire = |name: &str, ty: Ty| b.wire(name, ty);
    let merge_valid = wire("merge_valid", bit);
    let merge_slot = wire("merge_slot", Ty::u(gb));
    let merge_hit = wire("merge_hit", bit);
    let merge_limit = wire("merge_limit", p.trav.dist_ty());
    let merge_sp = wire("merge_sp", Ty::u(p.trav.sp_width()));
    let free_valid = wire("free_valid", bit);
    let free_slot = wire("free_slot", Ty::u(gb));
    let leaf_pop: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_leaf_pop"), bit)).collect();
    let done_pop: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_done_pop"), bit)).collect();
    let unit = Rc::new(traverse_core(&p.trav, scene));
    let node_words: Vec<S> =
        (0..units).map(|u| b.wire(&format!("u{u}_node_word"), Ty::u(scene.node.0.width))).collect();
    let trav: Vec<_> = (0..units)
        .map(|u| {
            let mine = is_unit(gslot, u, sb, ub);
            let we = (accept & mine).name(&format!("u{u}_alloc"));
            let new_valid = (box_done & is_unit(box_done_slot, u, sb, ub)).name(&format!("u{u}_new"));
            let mv = (merge_valid & is_unit(merge_slot, u, sb, ub)).name(&format!("u{u}_merge"));
            let fv = (free_valid & is_unit(free_slot, u, sb, ub)).name(&format!("u{u}_free"));
            let ins = [
                we,
                turn_slot,
                ox,
                oy,
                oz,
                ix,
                iy,
                iz,
                new_valid,
                box_done_slot.slice(0, sb),
                box_tmax,
                box_miss,
                mv,
                merge_slot.slice(0, sb),
                merge_hit,
                merge_limit,
                merge_sp,
                fv,
                free_slot.slice(0, sb),
                we,
                leaf_pop[u as usize],
                done_pop[u as usize],
                node_words[u as usize],
            ];
            let t = b.instance(&format!("u_traverse_{u}"), &unit, &ins);
            b.drive(has_free_w[u as usize], t.get("has_free"));
            b.drive(free_idx_w[u as usize], t.get("free_slot_out"));
            t
        })
        .collect();
    // The node ROM: one per two units, on a block RAM's two ports.
    let (node_l, node_image) = (&scene.node.0, &scene.node.1);
    let image: Vec<u128> = node_image.iter().map(|w| word_bits(w, 0, node_l.width)).collect();
    for pair in 0..units.div_ceil(2) {
        let (u0, u1) = (2 * pair as usize, 2 * pair as usize + 1);
        let (label, nrc) = (format!("u_node_rom_{pair}"), p.trav.node_rom_cycles);
        if u1 < units as usize {
            let (a, c) = (trav[u0].get("node_addr"), trav[u1].get("node_addr"));
            let (wa, wc) = brom2(&b, &label, &format!("node_{scene_tag}"), node_l.width, image.clone(), a, c, nrc);
            b.drive(node_words[u0], wa);
            b.drive(node_words[u1], wc);
        } else {
            let w = brom(
                &b,
                &label,
                &format!("node_{scene_tag}"),
                node_l.width,
                image.clone(),
                trav[u0].get("node_addr"),
                nrc,
            );
            b.drive(node_words[u0], w);
        }
    }

    // The core's ray RAMs (origin and direction, for the pipeline), by global slot.
    let slots = p.total_slots() as usize;
    let o_mem = b.ram("ray_o", 3 * n, vec![0; slots]);
    b.ram_write(o_mem, accept, gslot, b.cat(&[oz, oy, ox]));
    // The directions in one RAM word while three fit a signal (m ≤ 42), else a RAM per axis.
    let w_rams: Vec<usize> = if 3 * p.isect.m <= MAX_WIDTH {
        let mem = b.ram("ray_w", 3 * p.isect.m, vec![0; slots]);
        b.ram_write(mem, accept, gslot, b.cat(&[wz.unsigned(), wy.unsigned(), wx.unsigned()]));
        vec![mem]
    } else {
        [("x", wx), ("y", wy), ("z", wz)]
            .into_iter()
            .map(|(axis, w)| {
                let mem = b.ram(&format!("ray_w{axis}"), p.isect.m, vec![0; slots]);
                b.ram_write(mem, accept, gslot, w.unsigned());
                mem
            })
            .collect()
    };

    // The leaf stream: the leaf in flight (slot, next entry, entries left, tmin, sp), and the
    // next leaf taken, in turn, from a unit's queue when the last entry goes.
    let tp = &p.trav;
    let (leaf_l, leaf_words) = &scene.leaf;
    let leaf_bits = rom_addr_bits(leaf_words.len());
    let count_w = scene.node.0.field("count").width;
    let cur_valid = b.reg("leaf_active", bit, Some(0));
    let cur_slot = b.reg("leaf_slot", Ty::u(gb), None);
    let cur_ptr = b.reg("leaf_ptr", Ty::u(leaf_bits), None);
    let cur_left = b.reg("leaf_left", Ty::u(count_w), None);
    let cur_tmin = b.reg("leaf_tmin", Ty::u(tp.tmin_width()), None);
    let cur_sp = b.reg("leaf_sp", Ty::u(tp.sp_width()), None);
    let cur_first = b.reg("leaf_first_entry", bit, None);
    // Whether the entry now sent is the leaf's last: a register of its own (left = 1 next).
    let cur_last = b.reg("leaf_last", bit, None);
    let last_entry = (cur_valid & cur_last).name("leaf_last_entry");
    let can_take = (!cur_valid | last_entry).name("leaf_can_take");
    let leaf_turn = b.reg("leaf_turn", Ty::u(ub.max(1)), Some(0));
    // Each unit's next leaf waits in a register of the top's (`leaf_buf`), filled from the
    // unit's queue while empty: the arbiter then chooses among registers beside it, and the
    // queues (across the die) only feed a register each. A unit's queue pops a clock after it
    // is taken from (`traverse_core`), and its buffer is full in that clock anyway.
    let fields = ["leaf_slot", "leaf_first", "leaf_count", "leaf_tmin", "leaf_sp"];
    let bufs: Vec<(S, S, Vec<S>)> = trav
        .iter()
        .enumerate()
        .map(|(u, t)| {
            let full = b.reg(&format!("u{u}_leaf_buf_valid"), bit, Some(0));
            let fill = (t.get("leaf_valid") & !full).name(&format!("u{u}_leaf_fill"));
            b.drive(leaf_pop[u], fill);
            let held: Vec<S> = fields
                .iter()
                .map(|f| {
                    let r = b.reg(&format!("u{u}_buf_{f}"), t.get(f).ty(), None);
                    b.next_when(r, fill, t.get(f));
                    r
                })
                .collect();
            (full, fill, held)
        })
        .collect();
    let avail: Vec<S> = bufs.iter().map(|(full, _, _)| *full).collect();
    // Rotating priority: the unit after the last one served first.
    let mut pick: Option<(S, S)> = None; // (any, unit)
    for j in (0..units).rev() {
        // Candidate j places after leaf_turn: unit (leaf_turn + 1 + j) mod units.
        let cand = |u: u32| (u + 1 + j) % units;
        let sel_any = if units == 1 {
            avail[0]
        } else {
            b.case(
                leaf_turn,
                &(0..units).map(|t| (t as u128, avail[cand(t) as usize])).collect::<Vec<_>>(),
                b.konst(bit, 0),
            )
        };
        let sel_u = if units == 1 {
            b.konst(Ty::u(1), 0)
        } else {
            b.case(
                leaf_turn,
                &(0..units).map(|t| (t as u128, b.konst(Ty::u(ub), cand(t) as i128))).collect::<Vec<_>>(),
                b.konst(Ty::u(ub), 0),
            )
        };
        pick = Some(match pick {
            None => (sel_any, sel_u),
            Some((any, u)) => (sel_any | any, sel_any.select(sel_u, u)),
        });
    }
    let (any_leaf, pick_u) = pick.expect("one unit or more");
    let take = (can_take & any_leaf).name("leaf_take");
    for (u, &(full, fill, _)) in bufs.iter().enumerate() {
        let me = if units == 1 { take } else { (take & pick_u.eq(u as i128)).name(&format!("u{u}_leaf_take")) };
        b.next(full, fill | (full & !me));
    }
    if units > 1 {
        b.next_when(leaf_turn, take, pick_u);
    } else {
        b.next(leaf_turn, leaf_turn);
    }
    let sel = |port: &str| {
        let k = fields.iter().position(|f| *f == port).expect("a buffered leaf field");
        let v: Vec<S> = bufs.iter().map(|(_, _, held)| held[k]).collect();
        if units == 1 {
            v[0]
        } else {
            b.case(pick_u, &(0..units).map(|u| (u as u128, v[u as usize])).collect::<Vec<_>>(), v[0])
        }
    };
    let next_slot = if ub == 0 { sel("leaf_slot") } else { b.cat(&[pick_u, sel("leaf_slot")]) };
    b.next(cur_valid, take | (cur_valid & !last_entry));
    b.next(cur_slot, take.select(next_slot, cur_slot));
    b.next(cur_ptr, take.select(sel("leaf_first"), cur_ptr + 1));
    b.next(cur_left, take.select(sel("leaf_count"), cur_left - 1));
    b.next(cur_tmin, take.select(sel("leaf_tmin"), cur_tmin));
    b.next(cur_sp, take.select(sel("leaf_sp"), cur_sp));
    b.next(cur_first, take);
    b.next(cur_last, take.select(sel("leaf_count").eq(1), cur_left.eq(2)));

    // Emission: the leaf ROM at the entry, then the triangle ROMs at its word; the tag and the
    // ray (read from the ray RAMs at the slot) wait alongside.
    let leaf_image = leaf_words.iter().map(|w| word_bits(w, 0, leaf_l.width)).collect();
    let tri_num =
        brom(&b, "u_leaf_rom", &format!("leaf_{scene_tag}"), leaf_l.width, leaf_image, cur_ptr, tp.leaf_rom_cycles);
    let lrc = tp.leaf_rom_cycles;
    let tag = b.cat(&[last_entry, cur_first, cur_slot, cur_sp, cur_tmin, b.konst(Ty::u(tp.tri_bits), 0)]);
    let tag = b.delay_line("emit_tag", tag, lrc);
    let tag =
        b.cat(&[tag.slice(tp.tri_bits, tag.width() - tp.tri_bits), tri_num.resize(tp.tri_bits)]).name("emit_tag_tri");
    let emit_valid = b.valid_line("emit_valid", cur_valid, lrc);
    let (tri_l, tri_words) = &scene.tri;
    let addr = tri_num.resize(rom_addr_bits(tri_words.len())).name("tri_addr");
    let mut tri_fields: Vec<S> = Vec::new();
    for (k, group) in tri_rom_groups(&tri_l.fields).iter().enumerate() {
        let lsb = group[0].lsb;
        let width: u32 = group.iter().map(|f| f.width).sum();
        let image = tri_words.iter().map(|w| word_bits(w, lsb, width)).collect();
        let word =
            brom(&b, &format!("u_tri_rom_{k}"), &format!("tri_{k}_{scene_tag}"), width, image, addr, p.tri_rom_cycles);
        tri_fields.extend(group.iter().map(|f| field(&format!("tri_{}", f.name), word, f, lsb)));
    }
    let trc = p.tri_rom_cycles;
    let valid_d = b.valid_line("pipe_valid", emit_valid, trc);
    let tag_d = b.delay_line("pipe_tag", tag, trc);
    // The slot's ray, read as the triangle ROMs are (its RAM read is one of the clocks).
    let emit_slot = tag.slice(tp.tri_bits + tp.tmin_width() + tp.sp_width(), gb);
    let o_word = b.delay_line("pipe_o", b.read("ray_o_q", o_mem, emit_slot), trc - 1);
    let w_words: Vec<S> = w_rams
        .iter()
        .enumerate()
        .map(|(k, &mem)| {
            let suffix = if w_rams.len() == 1 { String::new() } else { ["x", "y", "z"][k].to_string() };
            b.delay_line(&format!("pipe_w{suffix}"), b.read(&format!("ray_w{suffix}_q"), mem, emit_slot), trc - 1)
        })
        .collect();
    let m = p.isect.m;
    let mut pipe_in = vec![valid_d, tag_d];
    pipe_in.extend((0..3).map(|a| o_word.slice(a * n, n)));
    pipe_in.extend(
        (0..3).map(|a| if w_words.len() == 1 { w_words[0].slice(a * m, m) } else { w_words[a as usize] }.signed()),
    );
    pipe_in.extend(tri_fields);
    let r = b.instance("u_intersect", &Rc::new(intersect_core(&p.isect)), &pipe_in);

    // Rays done: taken from the units' done queues, lowest unit first (a ray finishes once),
    // while the result queue has room for one more (`res_credit_ok`, below).
    let credit_ok = b.reg("res_credit_ok", bit, Some(1));
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
    for u in 1..units as usize {
        let mine = (dv[u] & !done_any).name(&format!("u{u}_done_take"));
        b.drive(done_pop[u], mine);
        done_slot = done_any.select(done_slot, b.cat(&[b.konst(Ty::u(ub), u as i128), trav[u].get("done_slot")]));
        done_any = done_any | dv[u];
    }
    let closest = Rc::new(closest_core(p.tag, p.total_slots(), p.trav.id_width, n, m, p.isect.target()));
    let mut cin: Vec<S> = r.all().to_vec();
    // Registered before the closest-hit unit, whose per-slot selects it drives (the units'
    // queues sit across the die).
    let (done_any, done_slot) = (b.valid_delay("done_valid_r", done_any), b.delay("done_slot_r", done_slot));
    cin.extend([accept, gslot, ray_id, done_any, done_slot]);
    let res = b.instance("u_closest", &closest, &cin);
    b.drive(merge_valid, res.get("merge_valid"));
    b.drive(merge_slot, res.get("merge_slot"));
    b.drive(merge_hit, res.get("merge_hit"));
    b.drive(merge_limit, res.get("merge_limit"));
    b.drive(merge_sp, res.get("merge_sp"));
    b.drive(free_valid, res.get("free_valid"));
    b.drive(free_slot, res.get("free_slot"));

    b.output("ray_ready", port_ready);
    super::result_queue::result_queue(&b, &res, done_any, res_ready, credit_ok);
    if debug {
        // Observation ports for `fxrt sim`: a triangle entering the pipeline, the deepest stack in
        // the units' N stages, node visits and culls this clock, slots holding a ray. The deepest
        // stack and the occupied slots come through a tree with a register after each level (a
        // clock per level of log2 U: a frame's maximum and sums hardly notice), so these counters
        // are never the core's slowest path (four units' chained maxima were: 102.5 MHz).
        b.output("busy", valid_d);
        let sum = |port: &str, w: u32| {
            trav.iter().map(|t| t.get(port).resize(w)).reduce(|a, c| a + c).expect("one unit or more")
        };
        fn tree<'b>(b: &'b Builder, name: &str, mut level: Vec<S<'b>>, join: impl Fn(S<'b>, S<'b>) -> S<'b>) -> S<'b> {
            let mut depth = 0;
            while level.len() > 1 {
                depth += 1;
                let next: Vec<S<'b>> =
                    level.chunks(2).map(|p| if p.len() == 2 { join(p[0], p[1]) } else { p[0] }).collect();
                level =
                    next.into_iter().enumerate().map(|(i, x)| b.delay(&format!("{name}_l{depth}_{i}"), x)).collect();
            }
            level[0]
        }
        let depths = trav.iter().map(|t| t.get("depth")).collect();
        b.output("stack_depth", tree(&b, "obs_depth", depths, |a, c| a.max(c)));
        b.output("visits", sum("visit", 3).name("visits_c"));
        b.output("culls", sum("cull", 3).name("culls_c"));
        let occupied = trav.iter().map(|t| t.get("occupied").resize(gb + 1)).collect();
        b.output("occupied", tree(&b, "obs_occupied", occupied, |a, c| a + c));
        // The walk of every slot (for the visit-order check): the ray written into a slot, and each
        // unit's node visits.
        b.output("accept", accept);
        b.output("accept_id", ray_id);
        b.output("accept_slot", gslot);
        for (u, t) in trav.iter().enumerate() {
            b.output(&format!("visit{u}"), t.get("visit"));
            b.output(&format!("visit{u}_slot"), t.get("visit_slot"));
            b.output(&format!("visit{u}_node"), t.get("visit_node"));
        }
    }
    let mut m = b.finish();
    m.std_ports = true;
    m
}

/// The core fed by the on-chip ray generator instead of the ray port (the thesis's demo):
/// no inputs but the clock and reset; the same result outputs (and observation outputs with
/// `debug`), every result taken the clock it is shown.
pub fn core_with_raygen(p: &CoreParams, scene: &SceneRoms, g: &crate::model::raygen::RayGen, debug: bool) -> Module {
    let mut m = Module::new(&format!("fxrt_core_raygen_{}", p.trav.scene_tag));
    m.std_ports = true;
    let generator = Rc::new(super::raygen::raygen_core(g, p.isect.n, p.isect.m, p.trav.c, p.trav.id_width));
    let ready = m.wire("ready", Ty::BIT);
    let rays = m.instance("u_raygen", &generator, &[ready]);
    let core = Rc::new(core_module_with(p, scene, debug));
    // Results are taken the clock they are shown.
    let mut ins = rays;
    ins.push(m.konst("res_ready", Ty::BIT, 1));
    let outs = m.instance("u_core", &core, &ins);
    for (k, (name, _)) in core.outputs.iter().enumerate() {
        if name == "ray_ready" {
            m.drive(ready, outs[k]);
        } else {
            m.output(name, outs[k]);
        }
    }
    m
}
