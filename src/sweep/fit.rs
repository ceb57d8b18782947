//! Fitting the core to a device (`--device`, issue 30): the shapes (traversal units U, ray
//! slots K per unit, intersection pipelines P) whose multipliers and block RAM the device
//! holds, each run on a short frame of the scene in the Rust simulator, and the one with the
//! most rays per clock. Unless given, the scene's leaf size and stack depth are searched too
//! (`SceneSearch`): each is a scene build of its own, and the tree they give is the one the
//! golden model walks.
//!
//! What a shape needs is counted from its netlist (`fpga::ecp5::blocks` on the LFE5U-85F:
//! nextpnr's own counts for every core placed; on the Xilinx parts `cores::cost::
//! dsp48e_estimate` and the RAMB36 sites of `fpga::xilinx_bram`, yosys's mapping). The core is
//! built with `base`'s multiplier cut (the CLI: the device's, unless `--dsp`). For each U and P only the most
//! slots that fit are run: more slots hide more of a parked ray's wait and never cost a clock.

use crate::cores::top::{CoreParams, CoreSpec, core_module_with};
use crate::error::{Error, Result};
use crate::fpga::device::Device;
use crate::model::camera::Camera;
use crate::params::Params;
use crate::scene::Scene;
use crate::scene::images::SceneRoms;
use crate::verify::feed::Stalls;
use crate::verify::frame::{frame_rays, simulate_rust};
use rayon::prelude::*;
use serde::Serialize;

/// Slots per unit tried, most first (48 is numbered, and built, as 64: not tried).
const SLOTS: [u32; 3] = [64, 32, 16];
/// The short frame each fitting shape runs (a side, pixels): long enough that 256 slots are
/// full most of the frame.
pub const FRAME: u32 = 48;
/// The share of the device's flip-flops a fitted core may take: nextpnr found no legal
/// placement for a core at 96 % of the LFE5U-85F's (4 × 64 slots, P = 2, before the rings of
/// `rtl::build::RING_FROM`), and placed the default core at 50 %; the rest is left to the
/// placer's packing (an ECP5 slice's two FFs share their clock enable and reset).
pub const FF_SHARE: f64 = 0.8;
/// The share of the device's LUTs a fitted core may take: the four-unit, two-pipeline core
/// placed at 77 % of the LFE5U-85F's LUT4 (at 124–134 MHz, its paths mostly routing).
pub const LUT_SHARE: f64 = 0.8;
/// Shapes within this fraction of the best on the scene as given are run on its other builds.
const CLOSE: f64 = 0.75;
/// The SAH node-step price the fit tries beside the scene's (`Params::sah_step_percent`): on
/// the teapot at leaves ≤ 4 and 5 it balances four units' node steps against two pipelines'
/// tests best (DECISIONS 139).
pub const FIT_SAH_STEP_PERCENT: u32 = 150;

/// Which of the scene's build parameters the fit may choose (those the user did not give).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneSearch {
    /// Leaves of one triangle fewer and one more than `--leaf-size` are tried too.
    pub leaf_size: bool,
    /// A stack of half the words (rounded to a power of two, as the stack RAM is) is tried too:
    /// the tree is then built no deeper than that.
    pub stack_depth: bool,
    /// With the SAH, `FIT_SAH_STEP_PERCENT` is tried too.
    pub sah_step: bool,
}

impl SceneSearch {
    pub const ALL: SceneSearch = SceneSearch { leaf_size: true, stack_depth: true, sah_step: true };

    /// The scene parameters tried from `p`, `p` first.
    fn variants(self, p: &Params) -> Vec<Params> {
        let leaves = if self.leaf_size {
            vec![p.leaf_size, p.leaf_size.saturating_sub(1), p.leaf_size + 1]
        } else {
            vec![p.leaf_size]
        };
        let words = crate::scene::rom::rom_depth(p.stack_depth as usize) as u32;
        let stacks = if self.stack_depth && words >= 2 { vec![p.stack_depth, words / 2] } else { vec![p.stack_depth] };
        let steps = if self.sah_step && p.tree == crate::params::TreeSplit::Sah {
            vec![p.sah_step_percent, FIT_SAH_STEP_PERCENT]
        } else {
            vec![p.sah_step_percent]
        };
        let mut out = Vec::new();
        for &leaf_size in &leaves {
            for &stack_depth in &stacks {
                for &sah_step_percent in &steps {
                    let v = Params { leaf_size, stack_depth, sah_step_percent, ..*p };
                    if v.validate().is_ok() && !out.contains(&v) {
                        out.push(v);
                    }
                }
            }
        }
        out
    }
}

/// One shape and what it needs of the device.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    /// The scene's largest leaf and stack entries (its tree) in this shape.
    pub leaf_size: u32,
    pub stack_depth: u32,
    /// The tree's SAH node-step price (`Params::sah_step_percent`; 0: none).
    pub sah_step_percent: u32,
    pub units: u32,
    pub slots: u32,
    pub pipelines: u32,
    /// MULT18X18D (LFE5U-85F) or DSP48E/DSP48E1 (Xilinx).
    pub multipliers: u32,
    /// DP16KD on the LFE5U-85F; RAMB36 sites on the Xilinx parts (two RAMB18 to a site).
    pub block_ram: u64,
    /// Flip-flops: the register bits left in the fabric (`Blocks::fabric_register_bits`, 5 %
    /// over nextpnr's count for the cores placed: synthesis drops what is constant).
    pub flip_flops: u64,
    /// LUTs: on the LFE5U-85F the LUT4 nextpnr places (`fpga::ecp5::luts`, with its carry and
    /// LUT-RAM cells), on the Xilinx parts the LUT6 of `Luts::lut6`.
    pub luts: u64,
    /// Rays per clock on the short frame (shapes that fit and are the most slots of their U, P).
    pub rays_per_clock: Option<f64>,
}

/// The fit: every shape counted, the one chosen.
#[derive(Clone, Debug, Serialize)]
pub struct Fit {
    pub device: Device,
    pub multipliers_of: u32,
    pub block_ram_of: u64,
    /// `FF_SHARE` of the device's flip-flops.
    pub flip_flops_of: u64,
    /// `LUT_SHARE` of the device's LUTs.
    pub luts_of: u64,
    pub frame: String,
    pub candidates: Vec<Candidate>,
    pub chosen: Candidate,
}

impl Candidate {
    const EMPTY: Candidate = Candidate {
        leaf_size: 0,
        stack_depth: 0,
        sah_step_percent: 0,
        units: 0,
        slots: 0,
        pipelines: 0,
        multipliers: 0,
        block_ram: 0,
        flip_flops: 0,
        luts: 0,
        rays_per_clock: None,
    };

    /// Whether the shape's needs are within the device's multipliers, block RAM and shares of
    /// flip-flops and LUTs.
    fn fits(&self, multipliers: u32, l: &Limits) -> bool {
        self.multipliers <= multipliers
            && self.block_ram <= l.block_ram
            && self.flip_flops <= l.flip_flops
            && self.luts <= l.luts
    }

    /// `base` (ray ids, divider, clock target) in this shape.
    pub fn spec(&self, base: &CoreSpec) -> CoreSpec {
        CoreSpec { units: self.units, slots: self.slots, pipelines: self.pipelines, ..*base }
    }
}

impl Fit {
    pub fn spec(&self, base: &CoreSpec) -> CoreSpec {
        self.chosen.spec(base)
    }

    /// What the fit found, a line per shape run and the choice.
    pub fn lines(&self) -> Vec<String> {
        let unit = if self.device == Device::Lfe5u85f { "" } else { " RAMB36" };
        let mut lines: Vec<String> = self
            .candidates
            .iter()
            .filter_map(|c| {
                let r = c.rays_per_clock?;
                Some(format!(
                    "device {}: {}: {} of {} multipliers, {} of {}{unit} block RAM, {} of {} FFs, {} of {} \
                     LUTs, {r:.4} rays per clock ({})",
                    self.device.name(),
                    c.shape(),
                    c.multipliers,
                    self.multipliers_of,
                    c.block_ram,
                    self.block_ram_of,
                    c.flip_flops,
                    self.flip_flops_of,
                    c.luts,
                    self.luts_of,
                    self.frame
                ))
            })
            .collect();
        lines.push(format!("device {}: chosen {}", self.device.name(), self.chosen.shape()));
        lines
    }
}

impl Candidate {
    /// "4 units × 64 slots, 2 pipelines, leaves ≤ 4, stack 16" (", SAH step 175 %" when priced).
    fn shape(&self) -> String {
        let step =
            if self.sah_step_percent > 0 { format!(", SAH step {} %", self.sah_step_percent) } else { String::new() };
        format!(
            "{} units × {} slots, {} pipelines, leaves ≤ {}, stack {}{step}",
            self.units, self.slots, self.pipelines, self.leaf_size, self.stack_depth
        )
    }
}

/// What a fitted core may take of a device besides its multipliers.
struct Limits {
    /// DP16KD on the LFE5U-85F, RAMB36 sites on the Xilinx parts.
    block_ram: u64,
    /// `FF_SHARE` of its flip-flops.
    flip_flops: u64,
    /// `LUT_SHARE` of its LUTs.
    luts: u64,
}

fn limits(device: Device) -> Limits {
    let cap = device.capacity();
    Limits {
        block_ram: cap.block_rams as u64,
        flip_flops: (cap.ffs as f64 * FF_SHARE) as u64,
        luts: (cap.luts as f64 * LUT_SHARE) as u64,
    }
}

/// What the fit counts block RAM in on `device`: DP16KD blocks, or RAMB36 sites.
fn block_ram_unit(device: Device) -> &'static str {
    if device == Device::Lfe5u85f { "block RAMs" } else { "RAMB36 (two RAMB18 to one)" }
}

/// What `device` lacks for core `p`, counted as the fit counts (its multipliers, block RAM,
/// `FF_SHARE` of its flip-flops, `LUT_SHARE` of its LUTs), in words; None when it holds the
/// core.
pub fn lacks(device: Device, roms: &SceneRoms, p: &CoreParams) -> Option<String> {
    let (multipliers, block_ram, flip_flops, luts) = needs(device, roms, p);
    let Limits { block_ram: block_ram_of, flip_flops: flip_flops_of, luts: luts_of } = limits(device);
    let (name, multipliers_of) = (device.name(), device.capacity().multipliers);
    let unit = block_ram_unit(device);
    if multipliers > multipliers_of {
        Some(format!("the core needs {multipliers} multipliers, the {name} has {multipliers_of}"))
    } else if block_ram > block_ram_of {
        Some(format!("the core needs {block_ram} {unit}, the {name} has {block_ram_of}"))
    } else if flip_flops > flip_flops_of {
        Some(format!("the core needs {flip_flops} flip-flops, more than {flip_flops_of} of the {name}'s"))
    } else if luts > luts_of {
        Some(format!("the core needs {luts} LUTs, more than {luts_of} of the {name}'s"))
    } else {
        None
    }
}

/// What core `p` needs of `device`: (multipliers, block RAM in the device's unit, flip-flops,
/// LUTs).
fn needs(device: Device, roms: &SceneRoms, p: &CoreParams) -> (u32, u64, u64, u64) {
    let core = core_module_with(p, roms, false);
    let b = crate::fpga::ecp5::blocks::blocks(&core);
    let luts = crate::fpga::ecp5::luts::luts(&core);
    match device {
        Device::Lfe5u85f => (b.mult18 as u32, b.dp16kd as u64, b.fabric_register_bits, luts.comb()),
        Device::Xc5vlx110t | Device::Xc7a100t => {
            let sites = crate::fpga::xilinx_bram::brams(&core).sites() as u64;
            (crate::cores::cost::dsp48e_estimate(&core), sites, b.fabric_register_bits, luts.lut6())
        }
    }
}

/// The shapes of one scene build whose U and P `keep` takes, counted, not yet run.
fn shapes(
    device: Device,
    scene: &Scene,
    roms: &SceneRoms,
    base: &CoreSpec,
    keep: &dyn Fn(u32, u32) -> bool,
) -> Vec<Candidate> {
    let mut shapes = Vec::new();
    for units in 1..=crate::cores::core_params::MAX_UNITS {
        for pipelines in [1, 2, 4].into_iter().filter(|p| units.is_multiple_of(*p) && keep(units, *p)) {
            for slots in SLOTS {
                let (leaf_size, stack_depth) = (scene.params.leaf_size, scene.params.stack_depth);
                let sah_step_percent = scene.params.sah_step_percent;
                let c =
                    Candidate { leaf_size, stack_depth, sah_step_percent, units, slots, pipelines, ..Candidate::EMPTY };
                // Shapes the closest-hit units cannot number (more than 128 slots a lane).
                if CoreParams::shaped(roms, &c.spec(base)).check().is_ok() {
                    shapes.push(c);
                }
            }
        }
    }
    shapes.par_iter_mut().for_each(|c| {
        (c.multipliers, c.block_ram, c.flip_flops, c.luts) =
            needs(device, roms, &CoreParams::shaped(roms, &c.spec(base)));
    });
    shapes
}

/// Runs, of `shapes` (one scene build's, most slots first), the most slots that `fits` per U
/// and P on `rays`, filling in their rays per clock.
fn run_shapes(
    shapes: &mut [Candidate],
    fits: &dyn Fn(&Candidate) -> bool,
    roms: &SceneRoms,
    rays: &[crate::verify::frame::PixelRay],
    base: &CoreSpec,
    progress: &(dyn Fn() + Sync),
) {
    let mut run: Vec<usize> = Vec::new();
    for (k, c) in shapes.iter().enumerate() {
        let taken = run.iter().any(|&j| (shapes[j].units, shapes[j].pipelines) == (c.units, c.pipelines));
        if fits(c) && !taken {
            run.push(k);
        }
    }
    let measured: Vec<(usize, f64)> = run
        .par_iter()
        .map(|&k| {
            let p = CoreParams::shaped(roms, &shapes[k].spec(base));
            let (_, stats) = simulate_rust(&p, roms, rays, &Stalls::none(), &|_| {});
            progress();
            (k, stats.rays_per_clock())
        })
        .collect();
    for (k, r) in measured {
        shapes[k].rays_per_clock = Some(r);
    }
}

/// The shapes of `base` (its id width, divider, clock target) for `scene` on `device` — with the
/// scene's leaf size and stack depth varied as `search` allows — and the one with the most rays
/// per clock on a `FRAME`² frame of the scene's default view (ties: the fewer multipliers, then
/// the less block RAM). Returns the fit and the scene build it chose. `progress` is called once
/// per shape run.
pub fn fit(
    device: Device,
    scene: &Scene,
    search: SceneSearch,
    base: &CoreSpec,
    progress: &(dyn Fn() + Sync),
) -> Result<(Fit, Scene)> {
    let cap = device.capacity();
    let limit = limits(device);
    // What no shape changes (widths, the clock) is said as itself, before any shape is tried.
    CoreParams::shaped(&SceneRoms::of(scene), &CoreSpec { units: 1, slots: 1, pipelines: 1, ..*base }).check()?;
    let builds: Vec<Scene> = search.variants(&scene.params)[1..]
        .par_iter()
        .map(|p| Scene::build(&scene.name, scene.world.clone(), p))
        .collect::<Result<_>>()?;
    let scenes: Vec<&Scene> = std::iter::once(scene).chain(&builds).collect();
    let fits = |c: &Candidate| c.fits(cap.multipliers, &limit);
    let cam = Camera::default_for(scene, FRAME, FRAME);
    // Every U and P on the scene as given; on its other builds only the U and P within `CLOSE`
    // of the best (a leaf or stack size moves the balance of units and pipelines a little, not
    // by a quarter): 11 runs instead of 36 for the teapot.
    let fitted = |v: usize, keep: &dyn Fn(u32, u32) -> bool| {
        let roms = SceneRoms::of(scenes[v]);
        let mut shapes = shapes(device, scenes[v], &roms, base, keep);
        run_shapes(&mut shapes, &fits, &roms, &frame_rays(scenes[v], &cam), base, progress);
        shapes
    };
    let mut candidates = fitted(0, &|_, _| true);
    let best = candidates.iter().filter_map(|c| c.rays_per_clock).fold(0.0, f64::max);
    let near = candidates.iter().filter(|c| c.rays_per_clock.is_some_and(|r| r >= CLOSE * best));
    let close: Vec<(u32, u32)> = near.map(|c| (c.units, c.pipelines)).collect();
    let others: Vec<Vec<Candidate>> =
        (1..scenes.len()).into_par_iter().map(|v| fitted(v, &|u, p| close.contains(&(u, p)))).collect();
    let mut of_build = vec![0; candidates.len()];
    for (v, more) in others.into_iter().enumerate() {
        of_build.extend(std::iter::repeat_n(v + 1, more.len()));
        candidates.extend(more);
    }
    let run: Vec<usize> = (0..candidates.len()).filter(|&k| candidates[k].rays_per_clock.is_some()).collect();
    let better = |a: &Candidate, b: &Candidate| {
        let (ra, rb) = (a.rays_per_clock.unwrap_or(0.0), b.rays_per_clock.unwrap_or(0.0));
        ra > rb || (ra == rb && (a.multipliers, a.block_ram) < (b.multipliers, b.block_ram))
    };
    let chosen = run.iter().copied().fold(None::<usize>, |best, k| match best {
        Some(b) if !better(&candidates[k], &candidates[b]) => Some(b),
        _ => Some(k),
    });
    let Some(chosen) = chosen else {
        return Err(Error::param(
            "device",
            format!(
                "{}: no core shape for scene {} fits its {} multipliers, {} {}, {} flip-flops ({} %) and {} LUTs \
                 ({} %)",
                device.name(),
                scene.name,
                cap.multipliers,
                limit.block_ram,
                block_ram_unit(device),
                limit.flip_flops,
                (FF_SHARE * 100.0).round(),
                limit.luts,
                (LUT_SHARE * 100.0).round()
            ),
        ));
    };
    let v = of_build[chosen];
    let chosen_scene = if v == 0 { scene.clone() } else { builds.into_iter().nth(v - 1).expect("a scene per build") };
    let fit = Fit {
        device,
        multipliers_of: cap.multipliers,
        block_ram_of: limit.block_ram,
        flip_flops_of: limit.flip_flops,
        luts_of: limit.luts,
        frame: format!("{FRAME}x{FRAME}, the scene's default view, Rust simulator"),
        chosen: candidates[chosen].clone(),
        candidates,
    };
    Ok((fit, chosen_scene))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scene::SceneSource;

    /// On the LFE5U-85F the teapot's fit is four units of 64 slots and two pipelines, its tree
    /// built for a stack of 16, leaves ≤ 5 and node steps priced (208 DP16KD with its pair ROMs,
    /// DECISIONS 137 and 139): with the stack
    /// of 32 asked for by default, four of 64 need 224 DP16KD of its 208 (four pipelines: 214 MULT18X18D of its 156). The XC5VLX110T's 64 DSP48E
    /// take two units with the products cut for them (60; three need 68), one with the ECP5's
    /// 18 × 18 cut (two need 70). Every shape run fits, and the chosen one has the most rays per
    /// clock of them; the scene returned is the chosen build.
    #[test]
    fn the_teapot_fits_four_units_of_64_and_two_pipelines_on_the_ecp5_and_two_units_on_the_virtex_5() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let base = CoreSpec { id_width: 12, ..CoreSpec::default() };
        let (ecp5, chosen) = fit(Device::Lfe5u85f, &scene, SceneSearch::ALL, &base, &|| {}).unwrap();
        let c = &ecp5.chosen;
        let got = (c.units, c.slots, c.pipelines, c.leaf_size, c.stack_depth, c.multipliers, c.block_ram);
        assert_eq!(got, (4, 64, 2, 5, 16, 134, 208), "{ecp5:#?}");
        assert_eq!(c.sah_step_percent, FIT_SAH_STEP_PERCENT);
        let p = &chosen.params;
        assert_eq!((p.leaf_size, p.stack_depth, p.sah_step_percent), (5, 16, FIT_SAH_STEP_PERCENT));
        let as_given = |c: &&Candidate| (c.units, c.slots, c.pipelines, c.stack_depth) == (4, 64, 2, 32);
        let four_64 =
            ecp5.candidates.iter().filter(|c| (c.leaf_size, c.sah_step_percent) == (4, 0)).find(as_given).unwrap();
        assert_eq!((four_64.block_ram, four_64.rays_per_clock), (224, None));
        let run: Vec<&Candidate> = ecp5.candidates.iter().filter(|c| c.rays_per_clock.is_some()).collect();
        assert!(run.len() >= 9 && run.iter().all(|c| c.multipliers <= 156 && c.block_ram <= 208), "{run:#?}");
        assert!(run.iter().all(|r| r.rays_per_clock <= c.rays_per_clock));
        assert!(run.iter().all(|r| r.flip_flops <= ecp5.flip_flops_of), "{run:#?}");
        assert_eq!((ecp5.flip_flops_of, ecp5.luts_of), (66_912, 66_912));
        // The chosen core's LUT4 as `fpga::ecp5::luts` counts them, near the 64,321 placed.
        assert!(run.iter().all(|r| r.luts <= ecp5.luts_of) && (60_000..66_912).contains(&c.luts), "{c:#?}");
        let dsp48 = CoreSpec { piece: Device::Xc5vlx110t.piece(), ..base };
        let (virtex, _) = fit(Device::Xc5vlx110t, &scene, SceneSearch::default(), &dsp48, &|| {}).unwrap();
        assert_eq!((virtex.chosen.units, virtex.chosen.pipelines, virtex.chosen.multipliers), (2, 1, 60));
        // Block RAM in RAMB36 sites as yosys maps the memories (`fpga::xilinx_bram`).
        assert_eq!((virtex.chosen.block_ram, virtex.block_ram_of), (94, 148));
        assert!(virtex.candidates.iter().all(|c| (c.leaf_size, c.stack_depth) == (4, 32)), "nothing searched");
        let three = virtex.candidates.iter().find(|c| (c.units, c.pipelines) == (3, 1)).unwrap();
        assert_eq!((three.multipliers, three.rays_per_clock), (68, None));
        let (square, _) = fit(Device::Xc5vlx110t, &scene, SceneSearch::default(), &base, &|| {}).unwrap();
        assert_eq!((square.chosen.units, square.chosen.multipliers), (1, 58));
    }

    /// A shape fits when each of its needs does: one over (multipliers, block RAM, or the
    /// flip-flops that kept a placeable 4 × 64 core out before the rings) and it does not.
    #[test]
    fn a_shape_fits_only_within_every_limit() {
        let c = Candidate { multipliers: 134, block_ram: 196, flip_flops: 47_501, luts: 64_321, ..Candidate::EMPTY };
        let l = limits(Device::Lfe5u85f);
        assert_eq!((l.block_ram, l.flip_flops, l.luts), (208, 66_912, 66_912));
        assert!(c.fits(156, &l));
        assert!(!c.fits(133, &l));
        assert!(!c.fits(156, &Limits { block_ram: 195, ..l }));
        assert!(!Candidate { flip_flops: 80_036, ..c }.fits(156, &l));
        assert!(!Candidate { luts: 66_913, ..c }.fits(156, &l));
    }

    /// The builds tried: the scene as given first, each other leaf size, stack and SAH step
    /// price only once and only where allowed; a stack halves to the power of two below its
    /// RAM's words; a step price only with the SAH.
    #[test]
    fn the_scene_builds_tried_are_the_given_one_then_the_allowed_neighbours() {
        let p = Params::default();
        let tried = |s: SceneSearch, p: &Params| -> Vec<(u32, u32, u32)> {
            s.variants(p).iter().map(|v| (v.leaf_size, v.stack_depth, v.sah_step_percent)).collect()
        };
        let leaf_and_stack = SceneSearch { sah_step: false, ..SceneSearch::ALL };
        assert_eq!(tried(SceneSearch::default(), &p), [(4, 32, 0)]);
        assert_eq!(tried(SceneSearch { stack_depth: true, ..SceneSearch::default() }, &p), [(4, 32, 0), (4, 16, 0)]);
        assert_eq!(tried(leaf_and_stack, &p), [(4, 32, 0), (4, 16, 0), (3, 32, 0), (3, 16, 0), (5, 32, 0), (5, 16, 0)]);
        let small = Params { leaf_size: 1, stack_depth: 20, ..p };
        assert_eq!(tried(leaf_and_stack, &small), [(1, 20, 0), (1, 16, 0), (2, 20, 0), (2, 16, 0)]);
        let f = FIT_SAH_STEP_PERCENT;
        assert_eq!(tried(SceneSearch { sah_step: true, ..SceneSearch::default() }, &p), [(4, 32, 0), (4, 32, f)]);
        assert_eq!(tried(SceneSearch::ALL, &p).len(), 12);
        let middle = Params { tree: crate::params::TreeSplit::Middle, ..p };
        assert_eq!(tried(SceneSearch { sah_step: true, ..SceneSearch::default() }, &middle), [(4, 32, 0)]);
    }
}
