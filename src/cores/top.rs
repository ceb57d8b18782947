//! The whole ray tracing core for one scene: ray stream in, closest hits out.
//!
//! ```text
//! ray_valid/ready, id, o, ω, 1/ω ─► traversal ─► leaf ROM ─► triangle ROMs ─► intersection ─► closest hit ─► res_*
//!                                  (FSM, node ROM, stack RAM)                 pipeline
//! ```
//!
//! The traversal emits one leaf entry per clock, two or three cycles after its `leaf` cycle
//! (the leaf ROM); the triangle ROMs add two or three more (`brom.rs`: three for block RAM,
//! whose fabric register follows the block's output register). The ray's origin and direction
//! come from the traversal's and the top's ray registers, which hold still until the next ray
//! is accepted — always after the ray's end token — through `ray_delay` more registers each:
//! pop, done and idle put the accepting edge three cycles after the last `leaf` cycle, and the
//! pipeline's input register takes that triangle's word leaf + triangle ROM cycles after it,
//! when only the delayed copy still holds the old ray.
//! The triangle table is wider than a signal may be (5 + 3n + 6m bits), so it is split into
//! ROMs of whole fields, ≤ 128 bits each, all read at the same address.

use super::brom::brom;
use super::closest::{TagLayout, closest_core};
use super::intersect::{IntersectParams, intersect_core};
use super::traverse::{TraverseParams, field, traverse_core, word_bits};
use crate::model::golden::GridRay;
use crate::rtl::build::{Builder, S};
use crate::rtl::width::MAX_WIDTH;
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use crate::scene::rom::Field;
use crate::scene::rom::rom_addr_bits;
use std::rc::Rc;

#[derive(Clone, Debug)]
pub struct CoreParams {
    pub isect: IntersectParams,
    pub trav: TraverseParams,
    pub tag: TagLayout,
    /// Clocks of a triangle ROM read (`brom::read_cycles`).
    pub tri_rom_cycles: u32,
}

impl CoreParams {
    pub fn new(scene: &SceneRoms, id_width: u32, div_bits: u32, target_mhz: u32) -> CoreParams {
        let trav = TraverseParams::new(scene, id_width, super::clock::ClockTarget(target_mhz));
        let tag = TagLayout { tri_bits: trav.tri_bits, tmin_bits: trav.tmin_width(), id_bits: id_width };
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
        CoreParams { isect, trav, tag, tri_rom_cycles: super::brom::read_cycles(scene.tri.1.len()) }
    }
    /// Cycles the ray's origin and direction are delayed on their way into the pipeline: its
    /// input register takes a ray's last triangle leaf_rom_cycles + tri_rom_cycles edges after
    /// the triangle's `leaf` cycle, and the next ray is accepted 3 edges after it at the
    /// earliest (pop, done, idle), so the ray registers may have changed that many cycles
    /// before.
    pub fn ray_delay(&self) -> u32 {
        self.trav.leaf_rom_cycles + self.tri_rom_cycles - 3
    }

    /// Rejects what the RTL layer cannot hold, naming the parameter to change.
    pub fn check(&self) -> crate::error::Result<()> {
        self.isect.check()?;
        let w = self.trav.n + 1 + self.trav.inv_width();
        if w > MAX_WIDTH {
            return Err(crate::error::Error::param(
                "c",
                format!(
                    "the traversal's plane distance needs n + m + C + 1 = {w} bits; the RTL layer holds {MAX_WIDTH}"
                ),
            ));
        }
        Ok(())
    }

    /// Rejects a scene whose ROMs do not fit `bram_kbits` of block RAM (each ROM rounded up
    /// to a power-of-two depth, as the printers emit it).
    pub fn check_device(&self, scene: &SceneRoms, bram_kbits: u64) -> crate::error::Result<()> {
        let stack =
            (self.trav.n as u64 * 2 + 6 + 32) * crate::scene::rom::rom_depth(self.trav.stack_depth as usize) as u64;
        let total = scene.rom_bits() + stack;
        if total > bram_kbits * 1024 {
            return Err(crate::error::Error::param(
                "bram-kbits",
                format!(
                    "scene {} needs {} Kb of ROM and stack, more than the {bram_kbits} Kb of block RAM allowed \
                     (the XC5VLX110T has 5328): use a smaller scene, a smaller --n/--m, or raise --bram-kbits \
                     for a larger device",
                    scene.name,
                    total.div_ceil(1024)
                ),
            ));
        }
        Ok(())
    }

    /// Cycles from a leaf entry leaving the traversal FSM to its result in the closest-hit
    /// unit's accumulator: leaf ROM, triangle ROMs, the pipeline, the unit's input stage.
    pub fn stream_latency(&self) -> u32 {
        self.trav.leaf_rom_cycles
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

pub fn core_module(p: &CoreParams, scene: &SceneRoms) -> Module {
    let b = Builder::new("fxrt_core");
    let ins: Vec<S> = core_inputs(p).iter().map(|(name, ty)| b.input(name, *ty)).collect();
    let [ray_valid, ray_id, ox, oy, oz, wx, wy, wz, ix, iy, iz] = ins[..] else { unreachable!("11 ray ports") };
    let trav =
        b.instance("u_traverse", &Rc::new(traverse_core(&p.trav, scene)), &[ray_valid, ray_id, ox, oy, oz, ix, iy, iz]);
    let (ready, emit_end, emit_tri) = (trav.get("ray_ready"), trav.get("emit_end"), trav.get("emit_tri"));

    // The direction, latched when the traversal accepts the ray.
    let accept = (ray_valid & ready).name("accept");
    let w = [("wx_r", wx), ("wy_r", wy), ("wz_r", wz)].map(|(name, s)| {
        let r = b.reg(name, s.ty(), None);
        b.next_when(r, accept, s);
        r
    });

    // Triangle ROMs at the emitted triangle number: block ROMs (`brom.rs`), the word two
    // cycles later; the tag and valid wait the same two cycles.
    let (tri_l, tri_words) = &scene.tri;
    let addr = emit_tri.resize(rom_addr_bits(tri_words.len())).name("tri_addr");
    let mut tri_fields: Vec<S> = Vec::new();
    for (k, group) in tri_rom_groups(&tri_l.fields).iter().enumerate() {
        let lsb = group[0].lsb;
        let width: u32 = group.iter().map(|f| f.width).sum();
        let image = tri_words.iter().map(|w| word_bits(w, lsb, width)).collect();
        let word = brom(&b, &format!("u_tri_rom_{k}"), &format!("tri_{k}"), width, image, addr, p.tri_rom_cycles);
        tri_fields.extend(group.iter().map(|f| field(&format!("tri_{}", f.name), word, f, lsb)));
    }
    // The tag: the end flag on top of the ray id (end token) or the leaf tmin and triangle.
    let payload = p.tag.payload();
    let tri_tmin = b.cat(&[trav.get("emit_tmin"), emit_tri.resize(p.tag.tri_bits)]).resize(payload);
    let tag = b.cat(&[emit_end, emit_end.select(trav.get("emit_id").resize(payload), tri_tmin)]).name("tag");
    let valid_d = b.delay_line("pipe_valid", trav.get("emit_valid"), p.tri_rom_cycles);
    let tag_d = b.delay_line("pipe_tag", tag, p.tri_rom_cycles);
    // The ray `ray_delay` cycles late, in step with the triangle words: the pipeline's input
    // register takes the ray's last triangle after the next ray's accept (see the module
    // comment), so it must still see the old origin and direction then.
    let cur_o =
        ["cur_ox", "cur_oy", "cur_oz"].map(|name| b.delay_line(&format!("pipe_{name}"), trav.get(name), p.ray_delay()));
    let w = [0, 1, 2].map(|k| b.delay_line(&format!("pipe_w{}", ["x", "y", "z"][k]), w[k], p.ray_delay()));

    let mut pipe_in = vec![valid_d, tag_d];
    pipe_in.extend(cur_o);
    pipe_in.extend(w);
    pipe_in.extend(tri_fields);
    let r = b.instance("u_intersect", &Rc::new(intersect_core(&p.isect)), &pipe_in);
    let closest = Rc::new(closest_core(p.tag, p.isect.n, p.isect.m, p.isect.target()));
    let res = b.instance("u_closest", &closest, r.all());
    b.output("ray_ready", ready);
    for (name, _) in &closest.outputs {
        b.output(name, res.get(name));
    }
    // Observation ports for `fxrt sim`: a triangle entering the pipeline, the stack depth.
    b.output("busy", (valid_d & !tag_d.bit(payload)).name("pipe_busy"));
    b.output("stack_depth", trav.get("stack_depth"));
    b.output("fsm_state", trav.get("fsm_state"));
    b.finish()
}

/// The core fed by the on-chip ray generator instead of the ray port (the thesis's demo):
/// no inputs but the clock and reset; the same result and observation outputs.
pub fn core_with_raygen(p: &CoreParams, scene: &SceneRoms, g: &crate::model::raygen::RayGen) -> Module {
    let mut m = Module::new("fxrt_core_raygen");
    let generator = Rc::new(super::raygen::raygen_core(g, p.isect.n, p.isect.m, p.trav.c, p.trav.id_width));
    let ready = m.wire("ready", Ty::BIT);
    let rays = m.instance("u_raygen", &generator, &[ready]);
    let core = Rc::new(core_module(p, scene));
    let outs = m.instance("u_core", &core, &rays);
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
    use crate::flow::feed::Stalls;
    use crate::flow::frame::{frame_rays, mismatches, simulate_rust, simulate_rust_cycle};
    use crate::model::camera::Camera;
    use crate::params::Params;
    use crate::scene::{Scene, SceneSource};

    #[test]
    fn a_small_frame_matches_the_golden_model() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        let p = CoreParams::new(&roms, 16, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 16, 16));
        let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
        assert_eq!(mismatches(&scene, &rays, &results), 0);
        assert!(results.iter().filter(|r| r.1.is_some()).count() > 20);
        assert!(stats.busy_cycles > 0 && stats.max_stack_depth > 0, "{stats:?}");
        // The batched engine (ray source in the netlist) and the cycle engine (ports driven
        // like a testbench) agree on every result and every count.
        let (cycle_results, cycle_stats) = simulate_rust_cycle(&p, &roms, &rays, &Stalls::none(), &|_| {});
        assert_eq!(cycle_results, results);
        assert_eq!(
            (cycle_stats.cycles, cycle_stats.busy_cycles, cycle_stats.max_stack_depth, &cycle_stats.state_cycles),
            (stats.cycles, stats.busy_cycles, stats.max_stack_depth, &stats.state_cycles)
        );
        assert_eq!(stats.state_cycles.iter().sum::<u64>(), stats.cycles);
    }
}
