//! `sweep --emit-slurm`: the sweep's shards as a Slurm job array with a merge job after it,
//! and the same as a GNU parallel command list, written into OUT/slurm.

use super::output::list;
use super::{SceneSpec, SweepSpec};
use crate::error::{Error, Result};
use crate::io::OutputSet;
use askama::Template;
use std::path::Path;

/// Slurm's default array limit: at most this many shards.
const MAX_SHARDS: usize = 1000;

/// `shards` is in 1..=min(configurations, MAX_SHARDS).
pub fn check_shards(shards: u32, configs: usize) -> Result<()> {
    let most = configs.min(MAX_SHARDS);
    if shards == 0 || shards as usize > most {
        return Err(Error::param(
            "shards",
            format!("{shards} is out of range: must be 1..={most} (configurations, and Slurm's array limit)"),
        ));
    }
    Ok(())
}

/// Writes the scripts for `shards` shards of the `configs` configurations of `spec` into
/// OUT/slurm, each shard on `cpus` threads. Paths are made absolute and the scripts call this
/// executable, so they run from anywhere on the cluster; every shard and the merge share the
/// cache folder `cache`.
pub fn emit(spec: &SweepSpec, configs: usize, out: &Path, cache: &Path, shards: u32, cpus: u32) -> Result<()> {
    check_shards(shards, configs)?;
    let abs = |p: &Path| std::path::absolute(p).map_err(|e| Error::file(p, e.to_string()));
    let exe = std::env::current_exe().map_err(|e| Error::new("fxrt", format!("cannot find its own path: {e}")))?;
    let files = slurm_files(&exe, spec, &abs(out)?, &abs(cache)?, shards, cpus)?;
    let mut set = OutputSet::new();
    for (name, text, executable) in &files {
        let path = out.join("slurm").join(name);
        if *executable {
            set.add_executable(&path, text.as_bytes())?;
        } else {
            set.add(&path, text.as_bytes())?;
        }
    }
    set.commit()
}

/// Quotes a word for a POSIX shell when it needs it.
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "_./,:=+-@%".contains(c)) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The command line that reproduces `spec` (without --out, --shard, --threads).
pub fn sweep_command(exe: &Path, spec: &SweepSpec) -> Vec<String> {
    let mut v = vec![exe.display().to_string(), "sweep".into()];
    let builtins: Vec<&str> = spec
        .scenes
        .iter()
        .filter_map(|s| match s {
            SceneSpec::Builtin(b) => Some(b.as_str()),
            SceneSpec::Obj(_) => None,
        })
        .collect();
    for s in &spec.scenes {
        if let SceneSpec::Obj(p) = s {
            v.push(p.display().to_string());
        }
    }
    if !builtins.is_empty() {
        v.extend(["--builtin".into(), builtins.join(",")]);
    }
    let c = &spec.camera;
    let vec3 = |x: [f64; 3]| format!("{},{},{}", x[0], x[1], x[2]);
    if let Some(e) = c.eye {
        v.extend(["--eye".into(), vec3(e)]);
    }
    if let Some(a) = c.at {
        v.extend(["--at".into(), vec3(a)]);
    }
    v.extend(["--up".into(), vec3(c.up), "--fov".into(), c.fov.to_string()]);
    v.extend(["--size".into(), format!("{}x{}", c.width, c.height)]);
    let join = |x: &[u32]| x.iter().map(u32::to_string).collect::<Vec<_>>().join(",");
    v.extend(["--n".into(), join(&spec.n), "--m".into(), join(&spec.m), "--t".into(), join(&spec.t)]);
    v.extend(["--c".into(), join(&spec.c), "--edge-shift".into(), list(&spec.edge_shift).replace(", ", ",")]);
    v.extend(["--leaf-size".into(), join(&spec.leaf_size)]);
    v.extend(["--stack-depth".into(), spec.stack_depth.to_string()]);
    if spec.tree != crate::params::TreeSplit::default() {
        v.extend(["--tree".into(), spec.tree.to_string()]);
    }
    if spec.one_at_a_time {
        v.push("--one-at-a-time".into());
    }
    if spec.synth {
        v.push("--synth".into());
    }
    if spec.core_sim {
        v.push("--core-sim".into());
    }
    if spec.target_mhz != crate::cores::clock::DEFAULT_TARGET_MHZ {
        v.extend(["--target-mhz".into(), spec.target_mhz.to_string()]);
    }
    if !spec.default_core_shape() {
        v.extend(["--slots".into(), join(&spec.slots), "--units".into(), join(&spec.units)]);
    }
    if let Some(e) = &spec.ecp5 {
        v.extend(["--family".into(), "ecp5".into(), "--seed".into(), e.seed.to_string()]);
        v.extend(["--modules".into(), e.modules.join(",")]);
    }
    v
}

#[derive(Template)]
#[template(path = "sweep.slurm", escape = "none")]
struct SlurmArray<'a> {
    shards: u32,
    cpus: u32,
    out: &'a str,
    /// The log folder for #SBATCH --output, where % starts a Slurm pattern.
    log_dir: &'a str,
    command: &'a str,
}

#[derive(Template)]
#[template(path = "sweep_merge.slurm", escape = "none")]
struct SlurmMerge<'a> {
    shards: u32,
    out: &'a str,
    log_dir: &'a str,
    merge: &'a str,
}

#[derive(Template)]
#[template(path = "sweep_submit.sh", escape = "none")]
struct SlurmSubmit<'a> {
    shards: u32,
    out: &'a str,
}

#[derive(Template)]
#[template(path = "sweep_parallel.sh", escape = "none")]
struct Parallel<'a> {
    shards: u32,
    cpus: u32,
    merge: &'a str,
}

/// The files of `--emit-slurm`: (name, contents, executable), to go into OUT/slurm/. Every
/// shard and the merge use the cache folder `cache`.
pub fn slurm_files(
    exe: &Path,
    spec: &SweepSpec,
    out: &Path,
    cache: &Path,
    shards: u32,
    cpus: u32,
) -> Result<Vec<(String, String, bool)>> {
    let render = |t: &dyn askama::DynTemplate| t.dyn_render().map_err(|e| Error::new("emit-slurm", e.to_string()));
    let quote = |v: &[String]| v.iter().map(|s| shell_quote(s)).collect::<Vec<_>>().join(" ");
    let cache_s = shell_quote(&cache.display().to_string());
    let command = format!("{} --cache {cache_s}", quote(&sweep_command(exe, spec)));
    let out_s = shell_quote(&out.display().to_string());
    // In #SBATCH --output a % starts a file-name pattern.
    let log_dir = out.join("slurm").display().to_string().replace('%', "%%");
    let shard_dirs: Vec<String> =
        (1..=shards).map(|i| shell_quote(&out.join(format!("shard-{i}")).display().to_string())).collect();
    let merge = format!(
        "{} sweep merge {} --out {out_s} --cache {cache_s}",
        shell_quote(&exe.display().to_string()),
        shard_dirs.join(" ")
    );
    let commands: String = (1..=shards)
        .map(|i| format!("{command} --threads {cpus} --shard {i}/{shards} --out {}\n", shard_dirs[i as usize - 1]))
        .collect();
    Ok(vec![
        (
            "sweep.slurm".into(),
            render(&SlurmArray { shards, cpus, out: &out_s, log_dir: &log_dir, command: &command })?,
            false,
        ),
        ("merge.slurm".into(), render(&SlurmMerge { shards, out: &out_s, log_dir: &log_dir, merge: &merge })?, false),
        ("submit.sh".into(), render(&SlurmSubmit { shards, out: &out_s })?, true),
        ("parallel.sh".into(), render(&Parallel { shards, cpus, merge: &merge })?, true),
        ("commands.txt".into(), commands, false),
    ])
}
