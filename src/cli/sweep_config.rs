//! `fxrt sweep`'s arguments validated: every list parsed and checked, the plan made, the
//! output and cache folders looked at, before anything runs or is written (`cli::config`).

use super::config::{ECP5_MODULES, threads};
use super::{SweepAction, SweepArgs};
use crate::error::{Error, Result};
use crate::io::check_folder;
use crate::params::Params;
use crate::sweep::{Plan, Shard, SweepSpec};
use std::path::PathBuf;

/// `fxrt sweep`: join shards, or run (a shard of) a sweep, or write its Slurm scripts.
#[derive(Debug)]
pub enum SweepConfig {
    Merge {
        dirs: Vec<PathBuf>,
        out: PathBuf,
        cache: Option<PathBuf>,
    },
    /// Boxed: a plan is large beside a merge.
    Run(Box<SweepRun>),
}

#[derive(Debug)]
pub struct SweepRun {
    pub spec: SweepSpec,
    pub plan: Plan,
    pub out: PathBuf,
    /// Default: OUT/cache.
    pub cache: PathBuf,
    pub threads: Option<usize>,
    pub shard: Option<Shard>,
    /// `--emit-slurm`: the shard count and the threads (CPUs) of each shard, default 4.
    pub slurm: Option<(u32, u32)>,
}

impl SweepArgs {
    pub fn config(&self) -> Result<SweepConfig> {
        if let Some(SweepAction::Merge(m)) = &self.action {
            check_folder(&m.out)?;
            m.cache.as_deref().map(check_folder).transpose()?;
            return Ok(SweepConfig::Merge { dirs: m.dirs.clone(), out: m.out.clone(), cache: m.cache.clone() });
        }
        let spec = self.spec()?;
        let plan = spec.plan()?;
        // clap requires --out without a subcommand; checked again so a hand-made SweepArgs
        // gets an error rather than a panic.
        let out = self.out.clone().ok_or_else(|| Error::param("out", "is required"))?;
        let threads = threads(self.threads)?;
        if self.emit_slurm && self.shard.is_some() {
            return Err(Error::param("emit-slurm", "writes the scripts for every shard: leave out --shard"));
        }
        // Refused here, before the sweep's first line (the cache folder is made as it starts).
        let cache = self.cache.clone().unwrap_or_else(|| out.join("cache"));
        check_folder(&out)?;
        check_folder(&cache)?;
        Ok(SweepConfig::Run(Box::new(SweepRun {
            cache,
            spec,
            plan,
            out,
            threads,
            shard: self.shard,
            slurm: self.emit_slurm.then(|| (self.shards, self.threads.unwrap_or(4) as u32)),
        })))
    }

    /// The sweep the arguments describe; every list is checked here, before anything runs.
    pub fn spec(&self) -> Result<SweepSpec> {
        use crate::sweep::{SceneSpec, values};
        // OBJ paths are made absolute, so a shard started elsewhere (Slurm) describes the same
        // sweep as a run from here.
        let mut scenes = Vec::new();
        for p in &self.scenes {
            scenes.push(SceneSpec::Obj(std::path::absolute(p).map_err(|e| Error::file(p, e.to_string()))?));
        }
        scenes.extend(self.builtin.iter().map(|b| SceneSpec::Builtin(b.trim().to_string())));
        if scenes.is_empty() {
            scenes.push(SceneSpec::Builtin("teapot".into()));
        }
        if !(self.camera.fov > 0.0 && self.camera.fov < 180.0) {
            return Err(Error::param("fov", format!("{} is out of range: must be in (0, 180)", self.camera.fov)));
        }
        let single = Params { stack_depth: self.stack_depth, tree: self.tree, ..Params::default() };
        single.validate()?;
        crate::cores::clock::ClockTarget(self.target_mhz).check()?;
        let mut spec = SweepSpec {
            scenes,
            camera: self.camera.spec(),
            n: values::parse_u32_list("n", &self.n)?,
            m: values::parse_u32_list("m", &self.m)?,
            t: values::parse_u32_list("t", &self.t)?,
            c: values::parse_u32_list("c", &self.c)?,
            edge_shift: values::parse_edge_shift_list(&self.edge_shift)?,
            leaf_size: values::parse_u32_list("leaf-size", &self.leaf_size)?,
            stack_depth: self.stack_depth,
            tree: self.tree,
            one_at_a_time: self.one_at_a_time,
            synth: self.synth,
            core_sim: self.core_sim,
            target_mhz: self.target_mhz,
            slots: values::parse_u32_list("slots", &self.slots)?,
            units: values::parse_u32_list("units", &self.units)?,
            pipelines: 1,
            device_fit: None,
            ecp5: self.ecp5()?,
            memory: self.memory.sweep()?,
        };
        if let Some(device) = self.device {
            fit_to(device, &mut spec)?;
        }
        Ok(spec)
    }

    /// `--family` and the options of ecp5 alone: the modules in `ECP5_MODULES` order, each
    /// once.
    fn ecp5(&self) -> Result<Option<crate::sweep::Ecp5Choice>> {
        let family = self.family.as_deref().unwrap_or("xc5v");
        match family {
            "ecp5" if !self.synth => Err(Error::param("family", "ecp5 places and routes with --synth: add --synth")),
            "ecp5" => {
                let given = self.modules.clone().unwrap_or_else(|| vec!["core".into()]);
                crate::fpga::ecp5::check_modules(&given)?;
                let modules = ECP5_MODULES.iter().filter(|m| given.iter().any(|g| g == *m)).map(|m| m.to_string());
                Ok(Some(crate::sweep::Ecp5Choice { modules: modules.collect(), seed: self.seed.unwrap_or(1) }))
            }
            "xc5v" if self.seed.is_some() => Err(Error::param("seed", "is nextpnr's: only with --family ecp5")),
            "xc5v" if self.modules.is_some() => {
                Err(Error::param("modules", "are placed and routed only with --family ecp5"))
            }
            "xc5v" => Ok(None),
            other => Err(Error::param("family", format!("'{other}' is not a sweep family: use xc5v or ecp5"))),
        }
    }
}

/// `--device`: every core of the sweep takes the shape fitted to `device` on the first scene at
/// the base set (`sweep::fit`, the scene's leaf size and stack as given: they are axes and
/// options of the sweep), so rows differ only by what is swept; the fit goes into the spec
/// (results.json) and its lines to stderr.
fn fit_to(device: crate::fpga::device::Device, spec: &mut SweepSpec) -> Result<()> {
    super::device::on_chip(spec.memory.is_some())?;
    let base = spec.base().params;
    let scene = crate::scene::Scene::load(&spec.scenes[0].source(), &base)?;
    let (width, height) = (spec.camera.width, spec.camera.height);
    let id_width = crate::scene::rom::addr_bits((width * height) as usize).max(1);
    let (target_mhz, piece) = (spec.target_mhz, device.piece());
    let core = crate::cores::top::CoreSpec { id_width, target_mhz, piece, ..Default::default() };
    let search = crate::sweep::fit::SceneSearch::default();
    let (fit, _) = super::device::fit_on_chip(device, &scene, search, &core, spec.memory.is_some())?;
    super::device::say(Some(&fit));
    let c = &fit.chosen;
    (spec.slots, spec.units, spec.pipelines) = (vec![c.slots], vec![c.units], c.pipelines);
    spec.device_fit = Some(serde_json::to_value(&fit).map_err(|e| Error::new("sweep", e.to_string()))?);
    Ok(())
}

impl super::args_hw::SweepMemoryArgs {
    /// `--memory external`'s fixed options and lists, each value checked; None on chip (where
    /// the lists are refused, naming the option).
    fn sweep(&self) -> Result<Option<crate::sweep::memory::MemorySweep>> {
        use super::args::{MemoryPlace, RayOrder};
        use crate::sweep::values::parse_u32_list;
        let lists = [
            ("mem-latency", &self.mem_latency),
            ("node-cache-kb", &self.node_cache_kb),
            ("tri-cache-kb", &self.tri_cache_kb),
        ];
        match self.memory {
            MemoryPlace::Auto => {
                return Err(Error::param(
                    "memory",
                    "a sweep names onchip or external (auto is per scene in sim and gen)",
                ));
            }
            MemoryPlace::Onchip => {
                if let Some((name, _)) = lists.iter().find(|(_, v)| v.is_some()) {
                    return Err(Error::param(name, "is an axis of external-memory sweeps: add --memory external"));
                }
                return Ok(None);
            }
            MemoryPlace::External => {}
        }
        let shape = self.shape.shape()?;
        crate::cores::memory_params::check_ways(self.cache_ways)?;
        let d = crate::sweep::memory::MemoryPoint::default();
        let list = |name: &str, v: &Option<String>, default: u32| match v {
            Some(text) => parse_u32_list(name, text),
            None => Ok(vec![default]),
        };
        let node_cache_kb = list("node-cache-kb", &self.node_cache_kb, d.node_cache_kb)?;
        let tri_cache_kb = list("tri-cache-kb", &self.tri_cache_kb, d.tri_cache_kb)?;
        for (flag, kbs) in [("node-cache-kb", &node_cache_kb), ("tri-cache-kb", &tri_cache_kb)] {
            for &kb in kbs {
                crate::cores::memory_params::check_cache_kb(flag, kb, shape.line_bytes, self.cache_ways)?;
            }
        }
        Ok(Some(crate::sweep::memory::MemorySweep {
            mem_bits: shape.mem_bits,
            cache_line: shape.line_bytes,
            ways: self.cache_ways,
            tiles: self.ray_order == RayOrder::Tiles,
            latency: list("mem-latency", &self.mem_latency, d.latency)?,
            node_cache_kb,
            tri_cache_kb,
        }))
    }
}
