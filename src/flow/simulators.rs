//! The external simulators, as one table (after MyHDL's `registerSimulator`): how to tell
//! whether each is installed, and how to compile and run a testbench directory with it.

use std::path::Path;
use std::process::Command;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Simulator {
    Ghdl,
    Iverilog,
    Verilator,
}

impl Simulator {
    pub const ALL: [Simulator; 3] = [Simulator::Ghdl, Simulator::Iverilog, Simulator::Verilator];

    pub fn name(self) -> &'static str {
        match self {
            Simulator::Ghdl => "ghdl",
            Simulator::Iverilog => "iverilog",
            Simulator::Verilator => "verilator",
        }
    }

    /// The executable this simulator needs.
    fn program(self) -> &'static str {
        match self {
            Simulator::Ghdl => "ghdl",
            Simulator::Iverilog => "iverilog",
            Simulator::Verilator => "verilator",
        }
    }

    pub fn available(self) -> bool {
        let flag = if self == Simulator::Iverilog { "-V" } else { "--version" };
        Command::new(self.program()).arg(flag).output().is_ok_and(|o| o.status.success())
    }

    /// Compiles and runs the testbench `tb` in `dir`, whose HDL files are `sources` (design
    /// first). Returns (passed, failed) from the testbench's closing line.
    pub fn run(self, dir: &Path, sources: &[&str], tb: &str) -> Result<(u64, u64), String> {
        self.run_timed(dir, sources, tb).map(|r| (r.passed, r.failed))
    }

    /// Like `run`, also timing the simulation step alone (not the compilation).
    pub fn run_timed(self, dir: &Path, sources: &[&str], tb: &str) -> Result<RunResult, String> {
        let steps: Vec<Vec<String>> = match self {
            Simulator::Ghdl => {
                let std = "--std=93c".to_string();
                let mut analyse = vec!["ghdl".into(), "-a".into(), std.clone(), "--workdir=.".into()];
                analyse.extend(sources.iter().map(|s| s.to_string()));
                vec![
                    analyse,
                    vec!["ghdl".into(), "-e".into(), std.clone(), "--workdir=.".into(), tb.into()],
                    vec!["ghdl".into(), "-r".into(), std, "--workdir=.".into(), tb.into()],
                ]
            }
            Simulator::Iverilog => {
                let mut compile =
                    vec!["iverilog".into(), "-g2005".into(), "-o".into(), "tb.vvp".into(), "-s".into(), tb.into()];
                compile.extend(sources.iter().map(|s| s.to_string()));
                vec![compile, vec!["vvp".into(), "-n".into(), "tb.vvp".into()]]
            }
            Simulator::Verilator => {
                let mut build: Vec<String> = [
                    "verilator",
                    "--binary",
                    "--timing",
                    "-j",
                    "2",
                    "-Wno-fatal",
                    "-Wno-lint",
                    "-Wno-style",
                    "--top-module",
                    tb,
                    "-o",
                    "tbsim",
                ]
                .iter()
                .map(|s| s.to_string())
                .collect();
                build.extend(sources.iter().map(|s| s.to_string()));
                vec![build, vec!["./obj_dir/tbsim".into()]]
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
        Ok(RunResult { passed, failed, seconds })
    }
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
