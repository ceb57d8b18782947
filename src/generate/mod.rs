//! `fxrt gen`: the cores' HDL, their JSON manifests, and the ISE project files; and the host
//! side of the AXI4-Stream wrapper (`axis_host`: ray and result packing, the C header, a
//! frame's stream files).

pub mod axis_host;
#[cfg(test)]
mod axis_tests;

use crate::cores::axis::{Layout, axis_module};
use crate::cores::intersect::{IntersectParams, intersect_core};
use crate::cores::top::{CoreParams, core_with_raygen};
use crate::model::raygen::RayGen;
use crate::rtl::emit;
use crate::rtl::netlist::Module;
use crate::scene::images::SceneRoms;
use askama::Template;
use serde_json::{Value, json};
use std::rc::Rc;

/// The JSON manifest written beside a core's HDL. `latency` is None for the whole core, whose
/// results come after a number of cycles that depends on the ray.
pub fn manifest(m: &Module, latency: Option<u32>, params: Value) -> Value {
    let port = |name: &str, dir: &str, ty: crate::rtl::Ty| json!({ "name": name, "direction": dir, "width": ty.width, "signed": ty.signed });
    let mut ports = vec![json!({ "name": "clk", "direction": "in", "width": 1, "signed": false })];
    if m.has_reset() {
        ports.push(json!({ "name": "rst", "direction": "in", "width": 1, "signed": false }));
    }
    // As printed: a bus (`rtl::bus`, an AXI4-Stream tdata) in place of its parts.
    ports.extend(m.printed_ports().iter().map(|p| port(p.name, if p.input { "in" } else { "out" }, p.ty)));
    let names = |ext: &str| m.hierarchy().iter().map(|x| format!("{}.{ext}", x.name)).collect::<Vec<_>>();
    let hex: Vec<String> = m.hierarchy().iter().flat_map(|x| emit::verilog::mem_files(x)).map(|f| f.0).collect();
    json!({
        "name": m.name,
        "generator": format!("fxrt {}", env!("CARGO_PKG_VERSION")),
        "latency_cycles": latency,
        "params": params,
        "ports": ports,
        "register_bits": m.register_bits(),
        "files": { "vhdl": names("vhd"), "verilog": names("v"), "verilog_memory_init": hex },
    })
}

/// The intersection pipeline and its divider for one parameter set: (module, latency,
/// manifest parameters).
pub fn cores(p: &IntersectParams) -> Vec<(Module, Option<u32>, Value)> {
    let ip = intersect_core(p);
    let div = p.divider();
    vec![
        (ip, Some(p.latency()), serde_json::to_value(p).unwrap_or(Value::Null)),
        (
            div,
            Some(p.div_latency()),
            json!({ "n": p.n, "bits_per_stage": p.div_bits, "num_width": p.num_width() - p.t, "den_width": p.den_width() - p.t }),
        ),
    ]
}

/// What `fxrt gen` writes besides the HDL.
#[derive(Clone, Copy, Debug)]
pub struct GenOptions {
    pub vhdl: bool,
    pub verilog: bool,
    /// ISE project script and UCF for the XC5VLX110T.
    pub ise: bool,
    /// The core's observation ports too (`core_module_with`).
    pub debug_ports: bool,
    pub clock_mhz: f64,
}

/// What `fxrt synth --family ecp5` measured of the core (`--measured`): its module's entry.
pub type Measured = Value;

/// Each placement seed of a measured report with its clock, in the order run: `[{seed,
/// fmax_mhz}]` (a one-seed report: that seed).
fn seed_figures(m: &Measured) -> Value {
    match m.get("seeds").and_then(Value::as_array) {
        Some(seeds) => {
            Value::Array(seeds.iter().map(|s| json!({ "seed": s["seed"], "fmax_mhz": s["fmax_mhz"] })).collect())
        }
        None => json!([{ "seed": m["seed"], "fmax_mhz": m["fmax_mhz"] }]),
    }
}

#[derive(Template)]
#[template(path = "ise_project.tcl", escape = "none")]
struct IseProject<'a> {
    top: &'a str,
    scene: &'a str,
    language: &'a str,
    files: &'a [String],
    /// Whether the project goes on to a bitstream: only for a board top, whose every port is
    /// on a pin of the board.
    bitstream: bool,
}

#[derive(Template)]
#[template(path = "board.ucf", escape = "none")]
struct BoardUcf<'a> {
    top: &'a str,
    period_ns: String,
}

/// The ISE project script for `top` (its UCF `top.ucf` beside it) from `files` in `language`,
/// run to the bitstream when `bitstream` (a board top) or else to the placed design's
/// timing and area reports.
pub fn ise_project(top: &str, scene: &str, language: &str, files: &[String], bitstream: bool) -> String {
    IseProject { top, scene, language, files, bitstream }.render().expect("ISE template renders") + "\n"
}

/// (file name, contents) of every module of `cores` in the chosen languages (each module
/// once), a manifest per core, and the ISE files for the first core when asked.
fn write_set(cores: &[(Module, Option<u32>, Value)], o: GenOptions, scene: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for (m, lat, params) in cores {
        for ext in [("vhd", o.vhdl), ("v", o.verilog)].iter().filter(|e| e.1).map(|e| e.0) {
            for (name, text) in emit::design_files(m, ext) {
                if !out.iter().any(|(n, _)| *n == name) {
                    out.push((name, text));
                }
            }
        }
        let text = serde_json::to_string_pretty(&manifest(m, *lat, params.clone())).unwrap_or_default() + "\n";
        out.push((format!("{}.json", m.name), text));
    }
    if let (true, Some((top, _, _))) = (o.ise, cores.first()) {
        let (language, ext) = if o.vhdl { ("VHDL", "vhd") } else { ("Verilog", "v") };
        let files: Vec<String> = top.hierarchy().iter().map(|x| format!("{}.{ext}", x.name)).collect();
        out.push((format!("{}.tcl", top.name), ise_project(&top.name, scene, language, &files, false)));
        let period_ns = format!("{:.3}", 1000.0 / o.clock_mhz);
        let ucf = BoardUcf { top: &top.name, period_ns }.render().expect("UCF template renders");
        out.push((format!("{}.ucf", top.name), ucf + "\n"));
    }
    out
}

/// The pipeline cores alone (intersection pipeline and divider).
pub fn files(p: &IntersectParams, vhdl: bool, verilog: bool) -> Vec<(String, String)> {
    write_set(
        &cores(p),
        GenOptions { vhdl, verilog, ise: false, debug_ports: false, clock_mhz: p.target_mhz as f64 },
        "",
    )
}

/// What the core needs of each device `--device` knows, counted from its netlist before any
/// synthesis: on the ECP5 the flow's own mapping (`fpga::ecp5::blocks`: MULT18X18D and DP16KD,
/// equal to what nextpnr placed for every core measured, and the LUT4 of `fpga::ecp5::luts`),
/// on the Xilinx parts yosys's slicing of each product into 25 × 18 DSP48s (`cores::cost`), its
/// block RAM mapping (`fpga::xilinx_bram`) and the LUT6 of `Luts::lut6`.
fn predicted(core: &Module) -> Value {
    use crate::fpga::device::Device;
    let b = crate::fpga::ecp5::blocks::blocks(core);
    let dsp = crate::cores::cost::dsp48e_estimate(core);
    let x = crate::fpga::xilinx_bram::brams(core);
    let luts = crate::fpga::ecp5::luts::luts(core);
    let of = |d: Device| d.capacity();
    json!({
        "how": "counted from the netlist by the flows' mapping rules, before synthesis (docs/HDL.md)",
        Device::Lfe5u85f.name(): {
            "mult18": b.mult18, "mult18_of": of(Device::Lfe5u85f).multipliers,
            "dp16kd": b.dp16kd, "dp16kd_of": of(Device::Lfe5u85f).block_rams,
            "lut_ram_bits": b.lut_ram_bits, "fabric_register_bits": b.fabric_register_bits,
            "lut4": luts.comb(), "lut4_of": of(Device::Lfe5u85f).luts,
        },
        Device::Xc5vlx110t.name(): {
            "dsp48e": dsp, "dsp48e_of": of(Device::Xc5vlx110t).multipliers,
            "ramb36": x.ramb36, "ramb18": x.ramb18, "ramb36_sites": x.sites(), "ramb36_sites_of": of(Device::Xc5vlx110t).block_rams,
            "lut6": luts.lut6(), "lut6_of": of(Device::Xc5vlx110t).luts,
        },
        Device::Xc7a100t.name(): {
            "dsp48e1": dsp, "dsp48e1_of": of(Device::Xc7a100t).multipliers,
            "ramb36": x.ramb36, "ramb18": x.ramb18, "ramb36_sites": x.sites(), "ramb36_sites_of": of(Device::Xc7a100t).block_rams,
            "lut6": luts.lut6(), "lut6_of": of(Device::Xc7a100t).luts,
        },
    })
}

/// The whole ray tracing core `core` (`core_module_with(p, roms, o.debug_ports)`, built once
/// by the caller) for a scene (fed by the on-chip ray generator when `raygen` is given), with
/// manifests for it and for each of its cores.
pub fn core_files(
    p: &CoreParams,
    roms: &SceneRoms,
    core: &Rc<Module>,
    o: GenOptions,
    raygen: Option<&RayGen>,
    measured: Option<&Measured>,
    device_fit: Option<&Value>,
) -> Vec<(String, String)> {
    let top = match raygen {
        Some(g) => core_with_raygen(p, core, g),
        None => (**core).clone(),
    };
    let core_params = json!({
        "scene": roms.name,
        "triangles": roms.tri_count(),
        "n": p.isect.n, "m": p.isect.m, "t": p.isect.t, "c": p.trav.c, "e": p.isect.e,
        "stack_depth": p.trav.stack_depth, "ray_id_width": p.trav.id_width, "div_bits": p.isect.div_bits, "target_mhz": p.isect.target_mhz,
        "intersection_latency_cycles": p.isect.latency(),
        "leaf_entry_to_result_cycles": p.stream_latency() + 1,
        "ray_slots_per_unit": p.trav.slots, "traversal_units": p.units, "intersection_pipelines": p.pipelines,
        "multiplier_pieces": p.trav.product.piece.label(),
        "results_in_order": false,
        "result_order": "rays finish out of order; every result carries its ray id (res_id)",
    });
    let min_latency = crate::verify::disturb::min_latency(core, p, roms);
    let mut set = vec![(top, None, core_params.clone())];
    // The core behind AXI4-Stream ports, with the C header of its layout (not for the core
    // fed by its own ray generator, which has no ray port); an external-memory core's read
    // port and `mem_base` pass through the wrapper unchanged.
    let axis = raygen.is_none().then(|| {
        let layout = Layout::of(&core);
        let wrapper = axis_module(&core, p);
        let header = (format!("{}.h", wrapper.name), axis_host::c_header(&wrapper.name, &layout));
        let params = json!({
            "core": core.name,
            "layout": layout,
            "c_header": header.0,
            "tlast": "s_axis_ray_tlast ends a frame: no ray is taken until every result of the frame has left; \
                      m_axis_res_tlast marks the frame's last result (docs/AXIS.md)",
        });
        set.push((wrapper, None, params));
        header
    });
    set.extend(cores(&p.isect));
    let mut out = write_set(&set, o, &roms.name);
    // The core's manifest (written first) gets what an integrator needs beyond its ports.
    let out_names: Vec<String> = out.iter().map(|f| f.0.clone()).collect();
    let ise: Vec<String> =
        out.iter().map(|f| f.0.clone()).filter(|n| n.ends_with(".tcl") || n.ends_with(".ucf")).collect();
    let file = &mut out.iter_mut().find(|f| f.0 == format!("{}.json", set[0].0.name)).expect("the core's manifest").1;
    let mut doc: Value = serde_json::from_str(file).expect("the manifest just written");
    let sha = |text: &str| {
        use sha2::{Digest, Sha256};
        format!("{:x}", Sha256::digest(text.as_bytes()))
    };
    let slots = p.slot_count() as u64;
    let queue = crate::cores::top::RESULT_QUEUE as u64;
    doc["latency_cycles"] = json!({
        "min": min_latency,
        "min_is": "clocks from the clock a ray is taken (ray_valid and ray_ready high) to the first clock its result is shown (res_valid), for a ray that leaves the scene box at once, in an idle core; every other ray takes longer",
        "max": null,
        "max_bound": format!("no constant bound: a ray's latency grows with its walk (node steps, leaves, triangle tests) and with the other rays sharing the core (at most {slots} in its slots), and stops while the consumer holds res_ready low; `fxrt sim` measures frames"),
    });
    doc["interface"] = json!({
        "reset_cycles": 1,
        "reset": "rst is synchronous and active high; one clock of it clears every valid bit (the ray port register, the traversal units' rings, queues and free slots, the leaf stream, the intersection pipeline, the closest-hit unit, the result queue): rays in flight and results not taken are dropped, nothing is transferred in that clock, and the core takes rays from the next clock on",
        "ray_handshake": "a ray is taken on a clock with ray_valid and ray_ready high; ray_ready comes from registers through one LUT (no path from ray_valid)",
        "ray_interval_min_cycles": 4,
        "result_handshake": "a result is taken on a clock with res_valid and res_ready high and holds res_* until then; no path from res_ready to any output",
        "result_queue_depth": queue,
        "rays_held_max": p.rays_held(),
        "rays_held_max_is": "rays taken whose results are not yet taken: the port register, the ray slots, the result queue and its output register",
        "results_in_order": false,
        "result_order": "rays finish out of order; every result carries its ray id (res_id)",
        "debug_ports": o.debug_ports,
    });
    let pick = |k: &str| measured.and_then(|m| m.get(k)).cloned().unwrap_or(Value::Null);
    doc["clock"] = json!({
        "target_mhz": p.isect.target_mhz,
        "measured_fmax_mhz": pick("fmax_mhz"),
        "measured_on": measured.map(|_| json!({ "device": pick("device"), "package": pick("package"), "speed_grade": pick("speed_grade"), "seed": pick("seed"), "yosys": pick("yosys"), "nextpnr": pick("nextpnr"), "module": pick("module") })),
        "measured_fmax_is": measured.map(|_| "the median over the placement seeds run (the lower middle one for an even count), never the best"),
        "measured_seeds": measured.map(|m| seed_figures(m)),
        "measured_fmax_min_mhz": pick("fmax_min_mhz"),
        "measured_fmax_max_mhz": pick("fmax_max_mhz"),
    });
    doc["resources"] = measured.map_or(
        Value::Null,
        |_| json!({ "lut4": pick("lut4"), "ff": pick("ff"), "mult18": pick("mult18"), "dp16kd": pick("dp16kd") }),
    );
    doc["predicted"] = predicted(core);
    // With `--device`: the shapes counted and run, and the one chosen (`sweep::fit`).
    if let Some(fit) = device_fit {
        doc["device_fit"] = fit.clone();
    }
    doc["hashes"] = json!({
        "scene_sha256": roms.hash(),
        "scene_tag": p.trav.scene_tag,
        "params_sha256": sha(&core_params.to_string()),
    });
    doc["files"]["ise"] = json!(ise);
    if let Some(m) = &p.mem {
        doc["memory"] = memory_manifest(m);
    }
    // Memory images only where the Verilog that reads them was written.
    let written = |n: &str| out_names.iter().any(|w| w == n);
    let hex: Vec<Value> = doc["files"]["verilog_memory_init"].as_array().cloned().unwrap_or_default();
    doc["files"]["verilog_memory_init"] =
        json!(hex.into_iter().filter(|h| h.as_str().is_some_and(written)).collect::<Vec<_>>());
    *file = serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n";
    if let Some(header) = &axis {
        let name = format!("{}.json", header.0.trim_end_matches(".h"));
        if let Some(f) = out.iter_mut().find(|f| f.0 == name) {
            f.1 = axis_manifest(&f.1, &doc, min_latency, crate::cores::axis::axis_rays_held(p));
        }
    }
    out.extend(axis);
    out
}

/// What an integrator needs to know of an external-memory core's read port and scene image.
fn memory_manifest(m: &crate::cores::memory_params::ExternalMemory) -> Value {
    json!({
        "where": "external: the scene image scene.bin (written beside the core) at byte address mem_base",
        "image": m.layout,
        "image_file": "scene.bin",
        "c_header": "fxrt_scene.h",
        "axi4_read": {
            "channels": "AR and R only (m_axi_ar*, m_axi_r*); RREADY is always 1",
            "data_bits": m.axi.data_bits,
            "address_bits": m.axi.addr_bits,
            "arlen": m.axi.line_beats - 1,
            "arsize": m.axi.arsize(),
            "arburst": "INCR (1)",
            "burst": "one cache line, line-aligned (never crosses 4 KB)",
            "id": "m_axi_arid is 0 on every read (one ID), so the memory returns bursts in order; m_axi_rid (1 bit) is not used",
            "outstanding_max": m.axi.outstanding,
            "errors": "mem_error (sticky until rst): a beat not asked for, RLAST where the burst's count does not end (or missing where it does), RRESP other than OKAY",
            "reset": "rst must also reset the memory side (ARESETn): bursts in flight are forgotten",
        },
        "node_cache_per_unit": { "kb": m.spec.node_cache_kb, "sets": m.node.sets, "ways": m.node.ways, "line_bytes": m.spec.shape.line_bytes },
        "tri_cache": { "kb": m.spec.tri_cache_kb, "sets": m.tri.sets, "ways": m.tri.ways, "line_bytes": m.spec.shape.line_bytes },
        "staging_records_per_slot": 1u32 << m.stage_bits,
    })
}

/// The AXI4-Stream wrapper's manifest `text` with what an integrator needs beyond its ports,
/// from the core's manifest `core` (its clock, measured resources, reset) and the core's
/// shortest latency: the wrapper adds `AXIS_ADDED_LATENCY` clocks, and holds `held` rays at
/// most (the core's, and two in its result register slice).
fn axis_manifest(text: &str, core: &Value, min_latency: Option<u64>, held: u32) -> String {
    let mut doc: Value = serde_json::from_str(text).expect("the manifest just written");
    let added = crate::cores::axis::AXIS_ADDED_LATENCY;
    doc["latency_cycles"] = json!({
        "min": min_latency.map(|m| m + added),
        "min_is": format!("clocks from the clock a ray is taken (s_axis_ray_tvalid and s_axis_ray_tready high) to the first clock its result is offered (m_axis_res_tvalid), for a ray that leaves the scene box at once, in an idle core: the core's minimum plus {added} (the wrapper's output register); every other ray takes longer"),
        "max": null,
        "max_bound": "no constant bound: a ray's latency grows with its walk and with the other rays sharing the core, and stops while m_axis_res_tready is low and while a frame's results drain (tlast); `fxrt sim` measures frames",
    });
    doc["interface"] = json!({
        "clock": "clk: every port is sampled and driven at its rising edge (one clock domain)",
        "reset_cycles": 1,
        "reset": "rst is synchronous and active high; one clock of it clears the core (see the core's manifest) and the wrapper's frame flag, ray count and result register slice: rays in flight and results not taken are dropped, nothing is transferred in that clock, and the wrapper takes rays from the next clock on",
        "ray_handshake": "AXI4-Stream: a ray is taken on a clock with s_axis_ray_tvalid and s_axis_ray_tready high; tready comes from registers (the core's ray port, the frame flag and count), with no path from tvalid or tdata",
        "result_handshake": "AXI4-Stream: a result is taken on a clock with m_axis_res_tvalid and m_axis_res_tready high; tvalid and tdata are registers and hold until taken; tlast is out_valid AND the frame flag AND (count = 1), all registers; m_axis_res_tready reaches only register enables",
        "rays_held_max": held,
        "results_in_order": false,
        "result_order": "rays finish out of order; every result carries its ray id (the id field of tdata)",
    });
    doc["clock"] = core["clock"].clone();
    if !core["memory"].is_null() {
        // The core's read port and mem_base are the wrapper's, unchanged.
        doc["memory"] = core["memory"].clone();
    }
    doc["resources"] = match &core["resources"] {
        Value::Null => Value::Null,
        r => json!({ "core": r, "wrapper": "not placed on its own: its registers are register_bits less the core's" }),
    };
    serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n"
}
