//! The memory side of an external-memory core (`--memory external`, docs/MEMORY.md): the AXI4
//! read port (`axi_read`), a node cache per traversal unit, and the triangle fetch
//! (`tri_fetch`) in front of the intersection pipeline. Askers of the read master: the units'
//! node caches (0 … U − 1), then the triangle cache (U).
//!
//! Ports (docs/MEMORY.md "The read port"): inputs `mem_base` and `m_axi_arready`,
//! `m_axi_rvalid`, `m_axi_rdata`, `m_axi_rlast`, `m_axi_rresp`, `m_axi_rid`; outputs
//! `m_axi_araddr`, `m_axi_arlen`, `m_axi_arsize`, `m_axi_arburst`, `m_axi_arid`,
//! `m_axi_arvalid`, `m_axi_rready`, `mem_error`.

use super::axi_read::{AxiIn, LineRequest, axi_read};
use super::cache::{Lookup, cache};
use super::core_params::CoreParams;
use super::leaf_stream::{Emission, RayRams};
use super::memory_params::ExternalMemory;
use super::tri_fetch::{FetchObserved, tri_fetch};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, Ports, S};

/// The memory inputs of the core, in port order.
pub fn memory_inputs(m: &ExternalMemory) -> Vec<(&'static str, Ty)> {
    vec![
        ("mem_base", Ty::u(m.axi.addr_bits)),
        ("m_axi_arready", Ty::BIT),
        ("m_axi_rvalid", Ty::BIT),
        ("m_axi_rdata", Ty::u(m.axi.data_bits)),
        ("m_axi_rlast", Ty::BIT),
        ("m_axi_rresp", Ty::u(2)),
        // One read ID (0), so bursts come back in order; RID is there for memories and
        // interconnects that have it (LiteDRAM's AXI port, cocotbext-axi), and not used.
        ("m_axi_rid", Ty::u(1)),
    ]
}

/// A port of the core's memory side (`memory_inputs` and the read master's outputs): what a
/// wrapper passes through unchanged.
pub fn is_memory_port(name: &str) -> bool {
    name == "mem_base" || name == "mem_error" || name.starts_with("m_axi_")
}

/// What each traversal unit's node cache drives into it: the record, hit, the fill to wait for,
/// the fills done (wires the top creates for the unit's instance).
pub type NodeIn<'b> = [S<'b>; 4];

/// What the memory side shows the observation ports.
pub struct MemoryObserved<'b> {
    /// Node lookups answered and hits this clock (summed over the units).
    pub node_looks: S<'b>,
    pub node_hits: S<'b>,
    pub tri: FetchObserved<'b>,
    /// A beat came in this clock (registered).
    pub beat: S<'b>,
}

/// The read master, the node caches (driving `node_in`) and the triangle fetch into the
/// pipeline. `inputs` are the core's memory inputs (`memory_inputs` order).
#[allow(clippy::too_many_arguments)]
pub fn memory_side<'b>(
    b: &'b Builder,
    p: &CoreParams,
    m: &ExternalMemory,
    inputs: &[S<'b>],
    trav: &[Ports<'b>],
    node_in: &[NodeIn<'b>],
    leaf_pop: &[S<'b>],
    rams: &RayRams,
) -> (Emission<'b>, MemoryObserved<'b>) {
    let units = trav.len();
    let ab = m.axi.addr_bits;
    let line_shift = m.spec.shape.line_bytes.trailing_zeros();
    let (node_region, tri_region) = m.regions();
    let bus = AxiIn { arready: inputs[1], rvalid: inputs[2], rdata: inputs[3], rlast: inputs[4], rresp: inputs[5] };
    let req: Vec<(S, S)> = (0..=units)
        .map(|k| (b.wire(&format!("mem_req{k}_valid"), Ty::BIT), b.wire(&format!("mem_req{k}_line"), Ty::u(ab))))
        .collect();
    let requests: Vec<LineRequest> = req.iter().map(|&(valid, offset)| LineRequest { valid, offset }).collect();
    let (out, fills) = axi_read(b, &m.axi, inputs[0], &requests, &bus);
    let offset = |line: S<'b>, region: u64| (line.resize(ab) << line_shift) + region as i128;

    b.stage("node_caches", "a node cache per traversal unit: looked up a clock after C, answered in N");
    let shift = m.node_line_shift();
    let mut looks = Vec::new();
    let mut hits = Vec::new();
    for (u, t) in trav.iter().enumerate() {
        // A tree with fewer nodes than a line holds has node numbers narrower than `shift`.
        let record = t.get("node_addr");
        let record = record.resize(record.ty().width.max(shift + 1));
        let rec = if shift == 0 {
            b.konst(Ty::u(m.node.rec_bits()), 0)
        } else {
            record.slice(0, shift).resize(m.node.rec_bits())
        };
        let line = (record >> shift).resize(m.node.line_bits);
        let look = Lookup { valid: t.get("node_look"), line, rec, cancel: Some(t.get("node_look_culled")) };
        let c = cache(b, &format!("nc{u}"), &m.node, &look, &fills[u]);
        let [word, hit, wait, done] = node_in[u];
        b.drive(word, c.answer.data[0]);
        b.drive(hit, c.answer.hit);
        b.drive(wait, c.answer.wait);
        b.drive(done, c.done);
        b.drive(req[u].0, c.request.0);
        b.drive(req[u].1, offset(c.request.1, node_region));
        looks.push(c.answer.valid.resize(3));
        hits.push((c.answer.valid & c.answer.hit).resize(3));
    }
    let tri_req = (b.wire("tri_req_valid", Ty::BIT), b.wire("tri_req_line", Ty::u(m.tri.line_bits)));
    b.drive(req[units].0, tri_req.0);
    b.drive(req[units].1, offset(tri_req.1, tri_region));
    let (emitted, tri) = tri_fetch(b, p, m, trav, leaf_pop, &fills[units], tri_req, rams);
    b.end_stage();
    b.output("m_axi_araddr", out.araddr);
    b.output("m_axi_arlen", out.arlen);
    b.output("m_axi_arsize", b.konst(Ty::u(3), m.axi.arsize() as i128));
    b.output("m_axi_arburst", b.konst(Ty::u(2), 1));
    b.output("m_axi_arid", b.konst(Ty::u(1), 0));
    b.output("m_axi_arvalid", out.arvalid);
    b.output("m_axi_rready", b.konst(Ty::BIT, 1));
    b.output("mem_error", out.error);
    let sum = |v: Vec<S<'b>>| v.into_iter().reduce(|a, c| a + c).expect("a unit");
    let observed = MemoryObserved {
        node_looks: sum(looks).name("node_looks_c"),
        node_hits: sum(hits).name("node_hits_c"),
        tri,
        beat: b.delay("mem_beat", fills.iter().map(|f| f.valid).reduce(|a, c| a | c).expect("an asker")),
    };
    (emitted, observed)
}
