"""Runs test_axis.py on a folder `fxrt gen --axis-frame` wrote, in one simulator:

    python run.py --sim ghdl|icarus|verilator --dir DIR --top fxrt_core_axis [--frame N] [--seed S]

GHDL simulates the VHDL files of the wrapper's manifest, Icarus and Verilator the Verilog ones
(reading their $readmemh images from DIR). Prints cocotb's summary and exits 1 unless the test
passed. Uses cocotb's Python runner (cocotb 1.8: the last release that runs Verilator 5.006).
"""

import argparse
import json
import os
import sys
from pathlib import Path

from cocotb.runner import get_results, get_runner


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", required=True, choices=["ghdl", "icarus", "verilator"])
    ap.add_argument("--dir", required=True, type=Path)
    ap.add_argument("--top", required=True)
    ap.add_argument("--frame", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    folder = a.dir.resolve()
    files = json.loads((folder / f"{a.top}.json").read_text())["files"]
    build = folder / f"cocotb_{a.sim}"
    here = Path(__file__).resolve().parent
    sys.path.insert(0, str(here))  # the runner hands sys.path to the simulator's Python
    runner = get_runner(a.sim)
    if a.sim == "ghdl":
        std = ["--std=93c"]
        runner.build(vhdl_sources=[folder / f for f in files["vhdl"]], hdl_toplevel=a.top, build_args=std, build_dir=build)
        test_dir, test_args = build, std  # the work library is in the build folder
    else:
        # Icarus as cocotb runs it (SystemVerilog rules, -g2012): the generated Verilog has no
        # logic that waits for a time-0 event, so it settles under these rules as under 2005's.
        icarus = ["-s", a.top]
        args = icarus if a.sim == "icarus" else ["-Wno-fatal", "-Wno-lint", "-Wno-style", "-O3"]
        runner.build(verilog_sources=[folder / f for f in files["verilog"]], hdl_toplevel=a.top, build_args=args, build_dir=build)
        test_dir, test_args = folder, []  # $readmemh finds the memory images here
    env = {"FXRT_AXIS_DIR": str(folder), "FXRT_AXIS_TOP": a.top, "FXRT_AXIS_FRAME": str(a.frame), "FXRT_AXIS_SEED": str(a.seed)}
    xml = runner.test(
        test_module="test_axis", hdl_toplevel=a.top, build_dir=build, test_dir=test_dir, test_args=test_args, extra_env=env
    )
    tests, failed = get_results(xml)
    print(f"cocotb {a.sim}: {tests - failed} passed, {failed} failed")
    sys.exit(0 if tests > 0 and failed == 0 else 1)


if __name__ == "__main__":
    os.environ.setdefault("MAKEFLAGS", "-j2")  # Verilator's C++ build
    main()
