"""The AXI4-Stream wrapper of fxrt's core, in any simulator cocotb drives (GHDL for the VHDL,
Icarus and Verilator for the Verilog): a frame of rays in with a random tvalid, results out
with a random tready, every result checked byte for byte against the golden model's.

Reads, from the folder FXRT_AXIS_DIR that `fxrt gen --axis-frame` wrote: the wrapper's manifest
(FXRT_AXIS_TOP.json: tdata widths and the id field), rays.bin (each ray's tdata, pixel order)
and expected.bin (the golden model's result tdata for each, the same order). FXRT_AXIS_FRAME
rays make a frame (tlast on the last; 0: no tlast) and FXRT_AXIS_SEED seeds the stalls.

Checks: every result equals the expected tdata of its id (flags, triangle, t, u, v, padding),
no id twice or unknown, none missing; with frames, tlast exactly on each frame's last result
and every result of a frame before it; a result offered and refused stays unchanged (AXI).

A core with its scene in external memory (the manifest has "memory") reads it through its AXI4
read port from a third-party model, cocotbext-axi's `AxiRamRead`, holding scene.bin at
FXRT_MEM_BASE (default 0x100000) and pausing RVALID at random (FXRT_AXIS_SEED); the test also
checks that the core read memory and never raised mem_error.
"""

import json
import logging
import os
import random
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, Timer


def read_manifest():
    folder = Path(os.environ["FXRT_AXIS_DIR"])
    return folder, json.loads((folder / (os.environ["FXRT_AXIS_TOP"] + ".json")).read_text())


class PortsOf:
    """Some of the DUT's ports, each looked up by name. cocotb-bus finds a bus's signals through
    dir(), which walks every signal of the design; in Verilator 5.006 (Debian 12's) that leaves
    the top's inputs unwritable (cocotb issue 3431, fixed in later Verilator releases)."""

    def __init__(self, dut, names):
        self._log, self._name = dut._log, dut._name
        self._handles = {n: getattr(dut, n) for n in names}

    def __dir__(self):
        return list(self._handles)

    def __getattr__(self, name):
        try:
            return self.__dict__["_handles"][name]
        except KeyError:
            raise AttributeError(name) from None


AXI_READ_SIGNALS = ["arid", "araddr", "arlen", "arsize", "arburst", "arvalid", "arready"] + [
    "rid", "rdata", "rresp", "rlast", "rvalid", "rready"
]


def external_memory(dut, folder, rng):
    """The scene image in cocotbext-axi's AXI4 read-only RAM behind the core's read port, with
    random R pauses; returns a list whose length counts the bursts asked for."""
    from cocotbext.axi import AxiRamRead, AxiReadBus

    image = (folder / "scene.bin").read_bytes()
    base = int(os.environ.get("FXRT_MEM_BASE", "0x100000"), 0)
    size = 1 << (base + len(image) - 1).bit_length()
    ports = PortsOf(dut, [f"m_axi_{n}" for n in AXI_READ_SIGNALS])
    ram = AxiRamRead(AxiReadBus.from_prefix(ports, "m_axi"), dut.clk, dut.rst, size=size)
    ram.write(base, image)
    ram.log.setLevel(logging.WARNING)  # not a line per burst
    dut.mem_base.value = base

    def pauses():
        while True:
            yield rng.random() < 0.3

    ram.r_channel.set_pause_generator(pauses())
    bursts = []

    async def count_bursts():
        while True:
            await FallingEdge(dut.clk)
            if int(dut.m_axi_arvalid.value) and int(dut.m_axi_arready.value):
                bursts.append(int(dut.m_axi_araddr.value))

    cocotb.start_soon(count_bursts())
    return bursts


def load():
    folder, manifest = read_manifest()
    layout = manifest["params"]["layout"]
    ray_bytes, res_bytes = layout["ray_bytes"], layout["res_bytes"]
    ray_id = next(f for f in layout["ray"] if f["name"] == "id")
    res_id = next(f for f in layout["res"] if f["name"] == "id")
    raw = (folder / "rays.bin").read_bytes()
    rays = [raw[k : k + ray_bytes] for k in range(0, len(raw), ray_bytes)]
    raw = (folder / "expected.bin").read_bytes()
    expected = [raw[k : k + res_bytes] for k in range(0, len(raw), res_bytes)]
    assert len(rays) == len(expected) and rays, "rays.bin and expected.bin of one frame"

    def field(data, f):
        return int.from_bytes(data[f["offset"] : f["offset"] + f["bytes"]], "little")

    ids = [field(r, ray_id) for r in rays]
    by_id = {field(e, res_id): e for e in expected}
    assert sorted(by_id) == sorted(ids), "expected.bin holds each ray's result"
    return rays, ids, by_id, res_bytes, lambda data: field(data, res_id)


@cocotb.test()
async def frame_with_random_valid_and_ready(dut):
    rays, ids, by_id, res_bytes, result_id = load()
    frame = int(os.environ.get("FXRT_AXIS_FRAME", "0"))
    rng = random.Random(int(os.environ.get("FXRT_AXIS_SEED", "1")))
    # Every input is driven before the first clock edge, so no register loads an undriven (X)
    # value; two simulator steps a period are exact in any time precision (Icarus has 1 s
    # without a timescale).
    dut.clk.value = 0
    dut.rst.value = 1
    dut.s_axis_ray_tvalid.value = 0
    dut.s_axis_ray_tlast.value = 0
    dut.s_axis_ray_tdata.value = 0
    dut.m_axis_res_tready.value = 0
    folder, doc = read_manifest()
    bursts = external_memory(dut, folder, random.Random(rng.random())) if "memory" in doc else None
    await Timer(1, units="step")
    cocotb.start_soon(Clock(dut.clk, 2, units="step").start())
    for _ in range(3):
        await FallingEdge(dut.clk)
    dut.rst.value = 0

    def is_last(k):
        return frame > 0 and ((k + 1) % frame == 0 or k + 1 == len(rays))

    got, lasts = [], []
    seen = set()
    nxt, offering, refused = 0, False, None
    cycles, done_at, waits, stalls = 0, None, 0, 0
    # Inputs change and outputs are read at the falling edge; the rising edge between takes a
    # ray when tvalid and tready were both 1, and a result likewise (no output depends on an
    # input in the same clock, so reading after driving sees the clock's values).
    while done_at is None or cycles < done_at + 200:
        await FallingEdge(dut.clk)
        cycles += 1
        assert cycles < 400 * len(rays) + 10_000, f"stopped after {len(got)} results" + (
            "" if bursts is None else f", {len(bursts)} bursts, mem_error {dut.mem_error.value}"
        )
        if not offering and nxt < len(rays) and rng.random() < 0.6:
            offering = True
            dut.s_axis_ray_tdata.value = int.from_bytes(rays[nxt], "little")
            dut.s_axis_ray_tlast.value = int(is_last(nxt))
        dut.s_axis_ray_tvalid.value = int(offering)
        ready = rng.random() < 0.5
        dut.m_axis_res_tready.value = int(ready)
        valid = int(dut.m_axis_res_tvalid.value) == 1
        if refused is not None:
            now = (int(dut.m_axis_res_tdata.value), int(dut.m_axis_res_tlast.value)) if valid else None
            assert now == refused, f"cycle {cycles}: a refused result changed or left"
            refused = None
        if valid:
            data = int(dut.m_axis_res_tdata.value).to_bytes(res_bytes, "little")
            last = int(dut.m_axis_res_tlast.value)
            if ready:
                rid = result_id(data)
                assert rid in by_id, f"a result for id {rid}, which no ray has"
                assert rid not in seen, f"a second result for id {rid}"
                seen.add(rid)
                assert data == by_id[rid], f"id {rid}: {data.hex()} expected {by_id[rid].hex()}"
                got.append(rid)
                lasts.append(last)
            else:
                refused = (int.from_bytes(data, "little"), last)
                stalls += 1
        if offering:
            if int(dut.s_axis_ray_tready.value) == 1:
                nxt += 1
                offering = False
            else:
                waits += 1
        if done_at is None and len(got) == len(rays):
            done_at = cycles
    assert len(got) == len(rays)
    if frame > 0:
        ends = [k for k, last in enumerate(lasts) if last]
        want = [k for k in range(len(rays)) if is_last(k)]
        assert ends == want, f"tlast on results {ends}, expected {want}"
        for k in range(0, len(rays), frame):
            assert sorted(got[k : k + frame]) == sorted(ids[k : k + frame]), f"frame {k // frame}"
    else:
        assert not any(lasts), "tlast without frames"
    assert waits > 0 and stalls > 0, "both sides stalled"
    if bursts is not None:
        assert bursts, "the core read no line from memory"
        assert int(dut.mem_error.value) == 0, "mem_error: a burst's RLAST or RRESP was wrong"
        dut._log.info(f"{len(bursts)} bursts read from AxiRamRead with random R pauses")
    dut._log.info(f"{len(got)} results matched in {cycles} cycles; source waited {waits}, sink stalled {stalls}")
