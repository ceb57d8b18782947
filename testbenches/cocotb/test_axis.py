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
"""

import json
import os
import random
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, Timer


def load():
    folder = Path(os.environ["FXRT_AXIS_DIR"])
    manifest = json.loads((folder / (os.environ["FXRT_AXIS_TOP"] + ".json")).read_text())
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
        assert cycles < 400 * len(rays) + 10_000, f"stopped after {len(got)} results"
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
    dut._log.info(f"{len(got)} results matched in {cycles} cycles; source waited {waits}, sink stalled {stalls}")
