//! The command line, in three layers: clap structs parsed with no side effects (here, with the
//! arguments in `args` and `args_hw`), each
//! command's arguments validated into a configuration before anything runs or any file is
//! written (`config`), and the commands run on those (`run`). `main.rs` only dispatches.

pub mod args;
pub mod args_hw;
pub mod bench_embree;
pub mod board;
pub mod config;
pub mod demo;
pub mod device;
pub mod exact;
pub mod placement;
pub mod run;
pub mod sweep_config;

use clap::{Parser, Subcommand};

pub use args::{
    BenchArgs, BenchWhat, CameraArgs, CompareArgs, FrameSim, HwArgs, ParamArgs, RenderArgs, SceneArgs, SceneChoice,
    ThreadArgs,
};
pub use args_hw::{
    DemoArgs, GenArgs, Lang, SimArgs, SimChoice, SweepAction, SweepArgs, SweepMergeArgs, SynthArgs, TestArgs,
};

#[derive(Parser, Debug)]
#[command(
    name = "fxrt",
    version,
    about = "Fixed-point hardware ray tracing: scene ROMs, a bit-exact golden model, float references and renders"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

impl Cli {
    /// The command given, or the main job on the embedded default: `fxrt demo` (the core
    /// generated for the teapot, a frame simulated and checked, both pictures, into fxrt-out/).
    pub fn command_or_default(self) -> Command {
        self.command.unwrap_or_else(|| {
            let job = Cli::parse_from(["fxrt", "demo"]);
            job.command.expect("the default job is a command")
        })
    }
}

/// A clap error as one line, like every other input error (`--help` has the details).
pub fn error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    text.lines().next().unwrap_or("invalid arguments").trim_start_matches("error: ").to_string()
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// The whole product on the embedded teapot (what `fxrt` alone runs): the core generated
    /// in VHDL and Verilog with its ROMs and manifest, a frame through it in the Rust
    /// simulator checked pixel by pixel against the golden model, both pictures, a summary.
    Demo(DemoArgs),
    /// Render a scene through a model (golden integer, f64, f32 or watertight).
    Render(RenderArgs),
    /// Quantise a scene, build its BIH and write the ROM images and scene.json.
    Scene(SceneArgs),
    /// Count where the golden model and a float reference disagree on a frame.
    Compare(CompareArgs),
    /// Measure golden-model render speed (teapot, primary rays).
    Bench(BenchArgs),
    /// Generate the HDL cores (VHDL-93, Verilog-2001) and their JSON manifests.
    Gen(GenArgs),
    /// Check the intersection pipeline against the golden model in a simulator.
    Test(TestArgs),
    /// Virtex-5 area of the cores from yosys (LUT, FF, DSP48E, BRAM), as JSON.
    Synth(SynthArgs),
    /// Run a whole frame through the generated ray tracing core and compare every pixel.
    Sim(SimArgs),
    /// Image error and hardware cost over lists of n, m, T, C and E: each takes values
    /// `12,16`, ranges `20..29` (inclusive) or steps `0..24:8`; `sweep merge` joins shards.
    Sweep(SweepArgs),
}

#[cfg(test)]
mod tests;
