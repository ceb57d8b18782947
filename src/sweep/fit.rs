//! Fitting the core to a device (`--device`, issue 30): the shapes (traversal units U, ray
//! slots K per unit, intersection pipelines P) whose multipliers and block RAM the device
//! holds, each run on a short frame of the scene in the Rust simulator, and the one with the
//! most rays per clock.
//!
//! What a shape needs is counted from its netlist (`fpga::ecp5::blocks` on the LFE5U-85F:
//! nextpnr's own counts for every core placed; `cores::cost::dsp48e_estimate` on the Xilinx
//! parts, with block RAM by bits as `--bram-kbits` counts it). For each U and P only the most
//! slots that fit are run: more slots hide more of a parked ray's wait and never cost a clock.

use crate::cores::top::{CoreParams, CoreSpec, core_module_with};
use crate::error::{Error, Result};
use crate::fpga::device::Device;
use crate::model::camera::Camera;
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

/// One shape and what it needs of the device.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    pub units: u32,
    pub slots: u32,
    pub pipelines: u32,
    /// MULT18X18D (LFE5U-85F) or DSP48E/DSP48E1 (Xilinx).
    pub multipliers: u32,
    /// DP16KD on the LFE5U-85F; on the Xilinx parts block RAM in Kb (ROMs and stacks).
    pub block_ram: u64,
    /// Rays per clock on the short frame (shapes that fit and are the most slots of their U, P).
    pub rays_per_clock: Option<f64>,
}

/// The fit: every shape counted, the one chosen.
#[derive(Clone, Debug, Serialize)]
pub struct Fit {
    pub device: Device,
    pub multipliers_of: u32,
    pub block_ram_of: u64,
    pub frame: String,
    pub candidates: Vec<Candidate>,
    pub chosen: Candidate,
}

impl Candidate {
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
        let unit = if self.device == Device::Lfe5u85f { "" } else { " Kb" };
        let mut lines: Vec<String> = self
            .candidates
            .iter()
            .filter_map(|c| {
                let r = c.rays_per_clock?;
                Some(format!(
                    "device {}: {} units × {} slots, {} pipelines: {} of {} multipliers, {}{unit} of {}{unit} block \
                     RAM, {r:.4} rays per clock ({})",
                    self.device.name(),
                    c.units,
                    c.slots,
                    c.pipelines,
                    c.multipliers,
                    self.multipliers_of,
                    c.block_ram,
                    self.block_ram_of,
                    self.frame
                ))
            })
            .collect();
        let c = &self.chosen;
        lines.push(format!(
            "device {}: chosen {} units × {} slots, {} pipelines",
            self.device.name(),
            c.units,
            c.slots,
            c.pipelines
        ));
        lines
    }
}

/// What the shape `spec` needs of `device`: (multipliers, block RAM in the device's unit).
fn needs(device: Device, roms: &SceneRoms, p: &CoreParams) -> (u32, u64) {
    let core = core_module_with(p, roms, false);
    match device {
        Device::Lfe5u85f => {
            let b = crate::fpga::ecp5::blocks::blocks(&core);
            (b.mult18 as u32, b.dp16kd as u64)
        }
        Device::Xc5vlx110t | Device::Xc7a100t => {
            (crate::cores::cost::dsp48e_estimate(&core), p.bram_bits(roms).div_ceil(1024))
        }
    }
}

/// The shapes of `base` (its id width, divider, clock target) for `scene` on `device`, and the
/// one with the most rays per clock on a `FRAME`² frame of the scene's default view (ties: the
/// fewer multipliers). `progress` is called once per shape run.
pub fn fit(device: Device, scene: &Scene, base: &CoreSpec, progress: &(dyn Fn() + Sync)) -> Result<Fit> {
    let roms = SceneRoms::of(scene);
    let cap = device.capacity();
    let block_ram_of = match device {
        Device::Lfe5u85f => cap.block_rams as u64,
        _ => device.bram_kbits(),
    };
    // What no shape changes (widths, the clock) is said as itself, before any shape is tried.
    CoreParams::shaped(&roms, &CoreSpec { units: 1, slots: 1, pipelines: 1, ..*base }).check()?;
    let mut candidates = Vec::new();
    for units in 1..=4u32 {
        for pipelines in [1, 2, 4].into_iter().filter(|p| units.is_multiple_of(*p)) {
            for slots in SLOTS {
                let mut c = Candidate { units, slots, pipelines, multipliers: 0, block_ram: 0, rays_per_clock: None };
                let p = CoreParams::shaped(&roms, &c.spec(base));
                // Shapes the closest-hit units cannot number (more than 128 slots a lane).
                if p.check().is_err() {
                    continue;
                }
                (c.multipliers, c.block_ram) = needs(device, &roms, &p);
                candidates.push(c);
            }
        }
    }
    let fits = |c: &Candidate| c.multipliers <= cap.multipliers && c.block_ram <= block_ram_of;
    // The most slots that fit, per (U, P).
    let mut run: Vec<usize> = Vec::new();
    for (k, c) in candidates.iter().enumerate() {
        let taken = run.iter().any(|&j| (candidates[j].units, candidates[j].pipelines) == (c.units, c.pipelines));
        if fits(c) && !taken {
            run.push(k);
        }
    }
    let cam = Camera::default_for(scene, FRAME, FRAME);
    let rays = frame_rays(scene, &cam);
    let measured: Vec<(usize, f64)> = run
        .par_iter()
        .map(|&k| {
            let p = CoreParams::shaped(&roms, &candidates[k].spec(base));
            let (_, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
            progress();
            (k, stats.rays_per_clock())
        })
        .collect();
    for (k, r) in measured {
        candidates[k].rays_per_clock = Some(r);
    }
    let better = |a: &Candidate, b: &Candidate| {
        let (ra, rb) = (a.rays_per_clock.unwrap_or(0.0), b.rays_per_clock.unwrap_or(0.0));
        ra > rb || (ra == rb && a.multipliers < b.multipliers)
    };
    let chosen = run.iter().map(|&k| &candidates[k]).fold(None::<&Candidate>, |best, c| match best {
        Some(b) if !better(c, b) => Some(b),
        _ => Some(c),
    });
    let Some(chosen) = chosen.cloned() else {
        return Err(Error::param(
            "device",
            format!(
                "{}: no core shape for scene {} fits its {} multipliers and {} {}",
                device.name(),
                scene.name,
                cap.multipliers,
                block_ram_of,
                if device == Device::Lfe5u85f { "block RAMs" } else { "Kb of block RAM" }
            ),
        ));
    };
    Ok(Fit {
        device,
        multipliers_of: cap.multipliers,
        block_ram_of,
        frame: format!("{FRAME}x{FRAME}, the scene's default view, Rust simulator"),
        candidates,
        chosen,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scene::SceneSource;

    /// On the LFE5U-85F the teapot's fit is four units of 32 slots and two pipelines: four of
    /// 64 need 212 DP16KD of its 208, four pipelines 214 MULT18X18D of its 156. The XC5VLX110T's
    /// 64 DSP48E take one unit (two need 70). Every shape run fits, and the chosen one has the
    /// most rays per clock of them.
    #[test]
    fn the_teapot_fits_four_units_and_two_pipelines_on_the_ecp5_and_one_unit_on_the_virtex_5() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let base = CoreSpec { id_width: 12, ..CoreSpec::default() };
        let ecp5 = fit(Device::Lfe5u85f, &scene, &base, &|| {}).unwrap();
        let c = &ecp5.chosen;
        assert_eq!((c.units, c.slots, c.pipelines, c.multipliers, c.block_ram), (4, 32, 2, 134, 196), "{ecp5:#?}");
        let four_64 = ecp5.candidates.iter().find(|c| (c.units, c.slots, c.pipelines) == (4, 64, 2)).unwrap();
        assert_eq!((four_64.block_ram, four_64.rays_per_clock), (212, None));
        let run: Vec<&Candidate> = ecp5.candidates.iter().filter(|c| c.rays_per_clock.is_some()).collect();
        assert!(run.len() >= 5 && run.iter().all(|c| c.multipliers <= 156 && c.block_ram <= 208), "{run:#?}");
        assert!(run.iter().all(|r| r.rays_per_clock <= c.rays_per_clock));
        let virtex = fit(Device::Xc5vlx110t, &scene, &base, &|| {}).unwrap();
        assert_eq!((virtex.chosen.units, virtex.chosen.pipelines, virtex.chosen.multipliers), (1, 1, 58));
    }
}
