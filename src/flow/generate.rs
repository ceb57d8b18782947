//! `fxrt gen`: the cores' HDL and their manifests.

use crate::cores::divider;
use crate::cores::intersect::{IntersectParams, intersect_core};
use crate::rtl::emit;
use crate::rtl::netlist::Module;
use serde_json::{Value, json};

/// The JSON manifest written beside a core's HDL.
pub fn manifest(m: &Module, latency: u32, params: Value) -> Value {
    let port = |name: &str, dir: &str, ty: crate::rtl::Ty| json!({ "name": name, "direction": dir, "width": ty.width, "signed": ty.signed });
    let mut ports = vec![json!({ "name": "clk", "direction": "in", "width": 1, "signed": false })];
    if m.has_reset() {
        ports.push(json!({ "name": "rst", "direction": "in", "width": 1, "signed": false }));
    }
    ports.extend(m.inputs.iter().map(|&i| port(&m.sig(i).name, "in", m.sig(i).ty)));
    ports.extend(m.outputs.iter().map(|(n, i)| port(n, "out", m.sig(*i).ty)));
    json!({
        "name": m.name,
        "generator": format!("fxrt {}", env!("CARGO_PKG_VERSION")),
        "latency_cycles": latency,
        "params": params,
        "ports": ports,
        "register_bits": m.register_bits(),
        "files": {
            "vhdl": emit::design_files(m, "vhd").into_iter().map(|f| f.0).collect::<Vec<_>>(),
            "verilog": emit::design_files(m, "v").into_iter().map(|f| f.0).collect::<Vec<_>>(),
        },
    })
}

/// Every core for one parameter set: (module, latency, manifest parameters).
pub fn cores(p: &IntersectParams) -> Vec<(Module, u32, Value)> {
    let ip = intersect_core(p);
    let div = p.divider();
    vec![
        (ip, p.latency(), serde_json::to_value(p).unwrap_or(Value::Null)),
        (
            div,
            divider::latency(p.n, p.div_bits),
            json!({ "n": p.n, "bits_per_stage": p.div_bits, "num_width": p.num_width() - p.t, "den_width": p.den_width() - p.t }),
        ),
    ]
}

/// (file name, contents) of everything `fxrt gen` writes.
pub fn files(p: &IntersectParams, vhdl_out: bool, verilog_out: bool) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (m, lat, params) in cores(p) {
        // A module shared by two cores (the divider) is written once.
        let mut push = |(name, text): (String, String)| {
            if !out.iter().any(|(n, _)| *n == name) {
                out.push((name, text));
            }
        };
        for ext in [("vhd", vhdl_out), ("v", verilog_out)].iter().filter(|e| e.1).map(|e| e.0) {
            emit::design_files(&m, ext).into_iter().for_each(&mut push);
        }
        let text = serde_json::to_string_pretty(&manifest(&m, lat, params)).unwrap_or_default() + "\n";
        out.push((format!("{}.json", m.name), text));
    }
    out
}
