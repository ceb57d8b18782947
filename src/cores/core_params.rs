//! What shapes a whole core (`top.rs`): its build options (`CoreSpec`), the parameters every
//! part of it derives from them (`CoreParams`), with the checks that name the parameter to
//! change, and its ray port's inputs.

use super::closest::TagLayout;
use super::intersect::IntersectParams;
use super::memory_params::{ExternalMemory, MemorySpec};
use super::traverse::TraverseParams;
use super::wide_ram::{GROUP_BITS, NARROW_GROUP_BITS, group_widths_of};
use crate::model::golden::GridRay;
use crate::rtl::Ty;
use crate::rtl::width::MAX_WIDTH;
use crate::scene::images::SceneRoms;
use crate::scene::rom::Field;
use crate::scene::rom::rom_addr_bits;

/// Ray slots per traversal unit and traversal units, by default (chosen by measurement:
/// docs/CORE.md).
pub const DEFAULT_SLOTS: u32 = 64;
pub const DEFAULT_UNITS: u32 = 2;
/// Traversal units a core may have. Eight keep two pipelines fed on the teapot (0.184 rays per
/// clock, DECISIONS 129) and are what every simulator has run; more fit none of `--device`'s
/// parts (eight units and two pipelines already take 182 multipliers).
pub const MAX_UNITS: u32 = 8;

#[derive(Clone, Debug)]
pub struct CoreParams {
    pub isect: IntersectParams,
    pub trav: TraverseParams,
    pub tag: TagLayout,
    /// Traversal units.
    pub units: u32,
    /// Intersection pipelines (lanes): lane l serves units l·U/P … (l + 1)·U/P − 1.
    pub pipelines: u32,
    /// Clocks of a triangle ROM read (`brom::tri_read_cycles`).
    pub tri_rom_cycles: u32,
    /// With the scene in external memory (`external`): its image, caches and read port.
    pub mem: Option<ExternalMemory>,
}

/// What shapes a core besides its scene: the width of its ray ids, the divider's quotient
/// bits per stage, the clock it is pipelined for, its ray slots per traversal unit, units and
/// intersection pipelines. `Default` is `fxrt gen`'s defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoreSpec {
    pub id_width: u32,
    pub div_bits: u32,
    pub target_mhz: u32,
    pub slots: u32,
    pub units: u32,
    pub pipelines: u32,
    /// The hard multiplier products are cut for: the ECP5's 18 × 18 unless the core is built
    /// for a Xilinx part (`--device`, `--board ml509`, `synth --family xc5v|xc7`).
    pub piece: super::mul::Piece,
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
            pipelines: 1,
            piece: super::mul::Piece::Mult18,
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
        let CoreSpec { id_width, div_bits, target_mhz, slots, units, pipelines, piece } = *shape;
        let mut trav = TraverseParams::new(scene, id_width, super::clock::ClockTarget(target_mhz), slots);
        trav.product = trav.product.with_piece(piece);
        let spread = super::clock::spread(units, super::clock::ClockTarget(target_mhz));
        if spread {
            trav.product = trav.product.landed();
            trav.spread = true;
        }
        if spread && pipelines > 1 {
            // Its units are its limit: a parent sends its near leaf child itself (DECISIONS
            // 137). With one pipeline the pipeline is (the four-unit throughput build keeps it
            // 97 % busy), and the pair ROMs would buy nothing.
            trav = trav.sending_leaves(scene);
        }
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
            piece,
            spread,
        };
        let tri_rom_cycles = super::brom::tri_read_cycles(scene.tri.1.len());
        CoreParams { isect, trav, tag, units, pipelines, tri_rom_cycles, mem: None }
    }

    /// The core of `shape` for `scene` in external memory (`--memory external`): no scene ROMs;
    /// the nodes through a cache per unit, the triangles through the triangle cache and the
    /// staging RAM (2 clocks to the pipeline).
    pub fn external(scene: &SceneRoms, shape: &CoreSpec, spec: MemorySpec) -> crate::error::Result<CoreParams> {
        let mut p = Self::shaped(scene, shape);
        let m = ExternalMemory::new(scene, spec)?;
        p.trav = p.trav.with_node_cache(&m.layout);
        p.trav.scene_tag = format!("{}_ext", p.trav.scene_tag);
        p.trav.leaf_rom_cycles = 0;
        p.tri_rom_cycles = 2;
        p.mem = Some(m);
        p.check_pipelines()?;
        Ok(p)
    }

    /// A name of lane `lane`'s: `l{lane}_{name}` with more than one pipeline, else `name`.
    pub fn lane_name(&self, lane: u32, name: &str) -> String {
        if self.pipelines > 1 { format!("l{lane}_{name}") } else { name.to_string() }
    }
    /// Bits of a lane (intersection pipeline) number: the top bits of a global slot number.
    pub fn lane_bits(&self) -> u32 {
        self.pipelines.trailing_zeros()
    }
    /// Whether global slot number `slot` is one of lane `lane`'s (its top bits are the lane).
    pub fn in_lane<'b>(&self, slot: crate::rtl::build::S<'b>, lane: u32) -> crate::rtl::build::S<'b> {
        slot.slice(self.lane_slot_bits(), self.lane_bits()).eq(lane as i128)
    }
    /// The widths of a lane's ray RAMs: the origins' (3n), then the directions' — one RAM of
    /// all three while they fit a signal (3m ≤ 128), else one per axis.
    pub fn ray_ram_widths(&self) -> Vec<u32> {
        let (n, m) = (self.isect.n, self.isect.m);
        if 3 * m <= MAX_WIDTH { vec![3 * n, 3 * m] } else { vec![3 * n, m, m, m] }
    }
    /// LUT-RAM groups of a lane's ray RAMs (`wide_ram`), in `ray_ram_widths` order: each is
    /// written from a write enable and an address register of its own.
    pub fn ray_ram_groups(&self) -> usize {
        let widths = self.ray_ram_widths().into_iter().enumerate();
        widths.map(|(k, w)| group_widths_of(w, self.ray_ram_group_bits(k)).len()).sum()
    }
    /// The widest group of a lane's ray RAM `k` (in `ray_ram_widths` order). A spread core
    /// reads its directions in narrow groups: the emission's slot register into a 16-bit
    /// group's 32 LUT-RAM cells (128 slots) and the select after them was a slowest path at a
    /// seed of the fitted core (`emit_slot` → `ray_w_q`, 6.95 ns). The origins keep wide
    /// groups: narrow ones everywhere cost the fitted core's LUT margin (a write decode per
    /// group and 16 words).
    pub fn ray_ram_group_bits(&self, k: usize) -> u32 {
        if self.isect.spread && k > 0 { NARROW_GROUP_BITS } else { GROUP_BITS }
    }
    /// Traversal units per lane.
    pub fn lane_units(&self) -> u32 {
        self.units / self.pipelines
    }
    /// Bits of a global slot number within its lane (the lane's slot numbers).
    pub fn lane_slot_bits(&self) -> u32 {
        self.tag.slot_bits - self.lane_bits()
    }

    /// The closest-hit unit of one lane: its slots, units and their numbers' bits.
    pub fn closest_module(&self) -> crate::rtl::Module {
        let lb = self.lane_bits();
        super::closest::closest_core(
            self.tag,
            self.total_slots() >> lb,
            [self.lane_units(), self.unit_bits() - lb, lb],
            self.trav.id_width,
            self.isect.n,
            self.isect.m,
            self.isect.target(),
        )
    }

    /// Bits of a unit number within a global slot number (0 for one unit).
    pub fn unit_bits(&self) -> u32 {
        self.tag.slot_bits - self.trav.slot_bits()
    }
    /// Global slot numbers of the core (unit bits above slot bits: a power of two per unit).
    pub fn total_slots(&self) -> u32 {
        self.units << self.trav.slot_bits()
    }
    /// Rays taken whose results are not yet taken, at most: the ray port's register, the
    /// slots, the result queue and its output register.
    pub fn rays_held(&self) -> u32 {
        self.slot_count() + super::result_queue::RESULT_QUEUE + 2
    }
    /// Ray slots of the core: the rays it holds at once.
    pub fn slot_count(&self) -> u32 {
        self.units * self.trav.slots
    }

    /// Rejects pipelines that cannot each serve units of their own, or a second pipeline beside
    /// external memory.
    fn check_pipelines(&self) -> crate::error::Result<()> {
        use crate::error::Error;
        let pl = self.pipelines;
        let lane_units = self.units / pl.max(1);
        if ![1, 2, 4].contains(&pl) || !self.units.is_multiple_of(pl) || (pl > 1 && !lane_units.is_power_of_two()) {
            return Err(Error::param(
                "pipelines",
                format!(
                    "{pl} is out of range: must be 1, 2 or 4 and divide --units ({}) into a power of two \
                     units per pipeline: each pipeline serves units of its own, numbered by the top bits",
                    self.units
                ),
            ));
        }
        if pl > 1 && self.mem.is_some() {
            return Err(Error::param(
                "pipelines",
                format!("{pl}: with the scene in external memory the core has one intersection pipeline (yet)"),
            ));
        }
        Ok(())
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
        if !(1..=MAX_UNITS).contains(&self.units) {
            return Err(Error::param("units", format!("{} is out of range: must be 1..={MAX_UNITS}", self.units)));
        }
        self.check_pipelines()?;
        // A lane's closest-hit unit keeps a bit per slot number of its lane in one word; a
        // unit's slot numbers take a power of two (3 units × 33 slots are numbered as 3 × 64).
        if self.total_slots() >> self.lane_bits() > MAX_WIDTH {
            let numbered = if self.total_slots() == self.slot_count() {
                String::new()
            } else {
                format!(", numbered as {} × {}", self.units, 1u32 << self.trav.slot_bits())
            };
            return Err(crate::error::Error::param(
                "slots",
                format!(
                    "{} units × {} slots = {} ray slots{numbered}; a closest-hit unit (one per pipeline) numbers \
                     at most {MAX_WIDTH}: fewer --slots or --units{}",
                    self.units,
                    self.trav.slots,
                    self.slot_count(),
                    if self.units.is_multiple_of(2 * self.pipelines) { ", or more --pipelines" } else { "" }
                ),
            ));
        }
        Ok(())
    }

    /// Bits of the units' stacks, as `check_device` counts them.
    pub fn stack_bits(&self) -> u64 {
        let stack_word = self.trav.n as u64 * 2 + 6 + 32;
        stack_word * crate::scene::rom::rom_depth(self.trav.stack_depth as usize) as u64 * self.total_slots() as u64
    }

    /// Bits of block RAM the core on chip takes: every copy of a scene ROM (the node ROM one
    /// per two units, the leaf and triangle ROMs one per two pipelines) at its power-of-two
    /// depth, and the stacks.
    pub fn bram_bits(&self, scene: &SceneRoms) -> u64 {
        let bits = |(l, w): &(crate::scene::rom::Layout, Vec<crate::scene::rom::Word>)| {
            l.width as u64 * crate::scene::rom::rom_depth(w.len()) as u64
        };
        let per_pair = |x: u32| x.div_ceil(2) as u64;
        bits(&scene.node) * per_pair(self.units)
            + (bits(&scene.tri) + bits(&scene.leaf)) * per_pair(self.pipelines)
            + self.stack_bits()
    }

    /// Rejects a scene whose ROMs do not fit `bram_kbits` of block RAM: every copy the units
    /// and pipelines read, each rounded up to a power-of-two depth as the printers emit it
    /// (`bram_bits`, as `--device` counts them).
    pub fn check_device(&self, scene: &SceneRoms, bram_kbits: u64) -> crate::error::Result<()> {
        let stack = self.stack_bits();
        if let Some(m) = &self.mem {
            return m.check_device(self.units, self.total_slots(), stack, bram_kbits);
        }
        let total = self.bram_bits(scene);
        if total > bram_kbits * 1024 {
            return Err(crate::error::Error::param(
                "bram-kbits",
                format!(
                    "scene {} needs {} Kb of ROM copies and stacks, more than the {bram_kbits} Kb of block RAM allowed \
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scene::{Scene, SceneSource};

    /// The block RAM check counts every ROM copy, as `--device` does: four units read two node
    /// ROMs, so an allowance that two units fit in refuses four, naming `--bram-kbits`; four
    /// pipelines copy the leaf and triangle ROMs too.
    #[test]
    fn the_block_ram_check_counts_every_rom_copy() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        let shape = |units, pipelines| CoreParams::shaped(&roms, &CoreSpec { units, pipelines, ..CoreSpec::default() });
        let (two, four, four_p4) = (shape(2, 1), shape(4, 1), shape(4, 4));
        let node_bits = four.bram_bits(&roms) - two.bram_bits(&roms) - (four.stack_bits() - two.stack_bits());
        assert!(node_bits > 0 && four_p4.bram_bits(&roms) > four.bram_bits(&roms));
        let allowed = two.bram_bits(&roms).div_ceil(1024);
        two.check_device(&roms, allowed).unwrap();
        let e = four.check_device(&roms, allowed).unwrap_err().to_string();
        assert!(e.contains("bram-kbits"), "{e}");
        four.check_device(&roms, four.bram_bits(&roms).div_ceil(1024)).unwrap();
        assert!(four_p4.check_device(&roms, four.bram_bits(&roms).div_ceil(1024)).is_err());
    }
}
