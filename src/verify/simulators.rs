//! The external simulators, as one table (after MyHDL's `registerSimulator`): how to tell
//! whether each is installed, and how to compile and run a testbench directory with it.

use crate::rtl::Module;
use std::path::Path;
use std::process::Command;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Simulator {
    Ghdl,
    /// Icarus under Verilog-2005 rules (`-g2005`).
    Iverilog,
    /// Icarus under SystemVerilog rules (`-g2012`, what cocotb's runner asks for): variable
    /// initialisers run before any process, so logic that waits for a time-0 event shows X.
    #[value(name = "iverilog-sv")]
    IverilogSv,
    Verilator,
}

impl Simulator {
    pub const ALL: [Simulator; 3] = [Simulator::Ghdl, Simulator::Iverilog, Simulator::Verilator];

    pub fn name(self) -> &'static str {
        match self {
            Simulator::Ghdl => "ghdl",
            Simulator::Iverilog => "iverilog",
            Simulator::IverilogSv => "iverilog-sv",
            Simulator::Verilator => "verilator",
        }
    }

    /// The executable this simulator needs.
    fn program(self) -> &'static str {
        match self {
            Simulator::Ghdl => "ghdl",
            Simulator::Iverilog | Simulator::IverilogSv => "iverilog",
            Simulator::Verilator => "verilator",
        }
    }

    /// Whether this simulator runs the Verilog testbenches written for Icarus.
    pub fn is_icarus(self) -> bool {
        matches!(self, Simulator::Iverilog | Simulator::IverilogSv)
    }

    pub fn available(self) -> bool {
        let flag = if self.is_icarus() { "-V" } else { "--version" };
        Command::new(self.program()).arg(flag).output().is_ok_and(|o| o.status.success())
    }

    /// Compiles and runs, in `dir`, the testbench files (`testbench::bench_files`) for `m`.
    /// Returns (passed, failed) from the testbench's closing line.
    pub fn run(self, dir: &Path, m: &Module) -> Result<(u64, u64), String> {
        self.run_timed(dir, m).map(|r| (r.passed, r.failed))
    }

    /// Like `run`, also timing the simulation: the Verilator harness times its clock loop
    /// itself; the others are timed as the whole simulation process (not the compilation).
    pub fn run_timed(self, dir: &Path, m: &Module) -> Result<RunResult, String> {
        self.run_bench(dir, m, Bench::Vectors).map(|(r, _)| r)
    }

    /// Runs the testbench of kind `bench` (its files already in `dir`); also returns the
    /// simulator's whole output, for the lines a stream testbench prints.
    pub fn run_bench(self, dir: &Path, m: &Module, bench: Bench) -> Result<(RunResult, String), String> {
        self.run_bench_with(dir, m, bench, &[])
    }

    /// `run_bench` with more design units compiled before the testbench (`extra`: module names
    /// whose files are in `dir`, e.g. the memory model).
    pub fn run_bench_with(
        self,
        dir: &Path,
        m: &Module,
        bench: Bench,
        extra: &[&str],
    ) -> Result<(RunResult, String), String> {
        let ext = if self == Simulator::Ghdl { "vhd" } else { "v" };
        let mut design: Vec<String> = m.hierarchy().iter().map(|x| format!("{}.{ext}", x.name)).collect();
        design.extend(extra.iter().map(|x| format!("{x}.{ext}")));
        let tb = tb_name(m);
        let words = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<String>>();
        let steps: Vec<Vec<String>> = match self {
            Simulator::Ghdl => {
                let mut analyse = words(&["ghdl", "-a", "--std=93c", "--workdir=."]);
                analyse.extend(design);
                analyse.push("tb.vhd".into());
                vec![
                    analyse,
                    words(&["ghdl", "-e", "--std=93c", "--workdir=.", &tb]),
                    words(&["ghdl", "-r", "--std=93c", "--workdir=.", &tb]),
                ]
            }
            Simulator::Iverilog | Simulator::IverilogSv => {
                let rules = if self == Simulator::Iverilog { "-g2005" } else { "-g2012" };
                let mut compile = words(&["iverilog", rules, "-o", "tb.vvp", "-s", &tb]);
                compile.extend(design);
                compile.push("tb.v".into());
                vec![compile, words(&["vvp", "-n", "tb.vvp"])]
            }
            Simulator::Verilator if bench == Bench::Stream => {
                // The stream testbench is Verilog with delays: Verilator's --binary --timing.
                let mut build = words(&[
                    "verilator",
                    "--binary",
                    "--timing",
                    "-O3",
                    "-j",
                    "2",
                    "-Wno-fatal",
                    "-Wno-lint",
                    "-Wno-style",
                    "--top-module",
                    &tb,
                    "-o",
                    "tbsim",
                ]);
                build.extend(design);
                build.push("tb.v".into());
                vec![build, words(&["./obj_dir/tbsim"])]
            }
            Simulator::Verilator => {
                let mut build = words(&[
                    "verilator",
                    "--cc",
                    "--exe",
                    "--build",
                    "-O3",
                    "-j",
                    "2",
                    "-Wno-fatal",
                    "-Wno-lint",
                    "-Wno-style",
                    "--top-module",
                    &m.name,
                    "-o",
                    "harness",
                ]);
                build.extend(design);
                build.push("harness.cpp".into());
                vec![build, words(&["./obj_dir/harness"])]
            }
        };
        let mut last = String::new();
        let mut seconds = 0.0;
        for step in steps {
            let mut cmd = Command::new(&step[0]);
            cmd.args(&step[1..]).current_dir(dir);
            if self == Simulator::Ghdl {
                // The LLVM back end simulates ~2x faster than mcode when it is installed.
                if Path::new("/usr/bin/ghdl-llvm").exists() {
                    cmd.env("GHDL_BACKEND", "llvm");
                }
            }
            let start = std::time::Instant::now();
            let out = cmd.output().map_err(|e| format!("{}: cannot run {}: {e}", self.name(), step[0]))?;
            seconds = start.elapsed().as_secs_f64();
            last = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
            if !out.status.success() {
                let tail: Vec<&str> = last.lines().rev().take(12).collect::<Vec<_>>().into_iter().rev().collect();
                return Err(format!("{}: `{}` failed:\n{}", self.name(), step.join(" "), tail.join("\n")));
            }
        }
        let (passed, failed) =
            parse_summary(&last).ok_or_else(|| format!("{}: no 'N passed, N failed' line in:\n{last}", self.name()))?;
        if let Some(s) = last.lines().find_map(|l| l.strip_prefix("simulation seconds ")) {
            seconds = s.trim().parse().unwrap_or(seconds);
        }
        Ok((RunResult { passed, failed, seconds }, last))
    }
}

/// Name of the testbench entity/module for `m` (GHDL and Icarus elaborate it; the testbench
/// generator names it so).
pub fn tb_name(m: &Module) -> String {
    format!("{}_tb", m.name)
}

/// The two kinds of testbench: fixed-latency vectors, or a ray stream with ready/valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bench {
    Vectors,
    Stream,
}

/// A testbench run: its counts and the seconds the simulation step took.
#[derive(Clone, Copy, Debug)]
pub struct RunResult {
    pub passed: u64,
    pub failed: u64,
    pub seconds: f64,
}

/// Finds the testbench's `N passed, M failed`, wherever the simulator put it on the line.
pub fn parse_summary(text: &str) -> Option<(u64, u64)> {
    text.lines().rev().find_map(|l| {
        let i = l.find(" passed, ")?;
        let passed = l[..i].rsplit(|c: char| !c.is_ascii_digit()).next()?.parse().ok()?;
        let rest = &l[i + " passed, ".len()..];
        let failed = rest.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok()?;
        Some((passed, failed))
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn summary_lines_of_each_simulator() {
        use super::parse_summary;
        assert_eq!(parse_summary("tb.vhd:80:5:@3us:(report note): 1000 passed, 0 failed"), Some((1000, 0)));
        assert_eq!(parse_summary("12 passed, 3 failed\n- tb.v:50: Verilog $finish"), Some((12, 3)));
        assert_eq!(parse_summary("nothing"), None);
    }
}
