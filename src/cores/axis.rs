//! The core behind two AXI4-Stream ports (ARM IHI 0051): rays in on `s_axis_ray_*`, results out
//! on `m_axis_res_*`, each ray and each result one transfer whose `tdata` holds every field on
//! whole bytes, little-endian (`Layout`, docs/AXIS.md). A `tlast` on a ray ends a frame: the
//! wrapper takes no ray after it until every result of the frame has left, and marks the
//! frame's last result with `tlast`.
//!
//! ```text
//! s_axis_ray_* ─► fields ─► core (ray port) ··· core (res_*) ─► output register ─► m_axis_res_*
//!                  tready = ray_ready ∧ ¬frame_end ∧ room      + skid register (res_ready)
//! ```
//!
//! Every output comes from registers: `tready` from the core's `ray_ready` (registers only)
//! and the wrapper's frame flag and count; the result side is a two-entry register slice
//! (output register and skid register), so `res_ready` into the core is a register too and
//! `m_axis_res_tready` reaches nothing but register enables.

use super::top::CoreParams;
use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};
use serde::Serialize;
use std::rc::Rc;

/// One field of a transfer: `bits` wide (`signed`: sign-extended, else zero-extended) in
/// `bytes` whole bytes from byte `offset`, little-endian.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Field {
    pub name: &'static str,
    pub offset: u32,
    pub bytes: u32,
    pub bits: u32,
    pub signed: bool,
}

/// Where every field sits in the ray and result `tdata`, and their widths in bytes (the
/// smallest power of two that holds the fields: AXI DMA engines and interconnects take only
/// those). The one place offsets are computed: the wrapper, the host packer (`generate::axis_host`),
/// the C header and the manifest all read them here.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Layout {
    pub ray: Vec<Field>,
    pub ray_bytes: u32,
    pub res: Vec<Field>,
    pub res_bytes: u32,
}

/// Ray fields in `tdata` order, with the core input each one drives.
pub const RAY_FIELDS: [(&str, &str); 10] = [
    ("id", "ray_id"),
    ("ox", "ox"),
    ("oy", "oy"),
    ("oz", "oz"),
    ("wx", "wx"),
    ("wy", "wy"),
    ("wz", "wz"),
    ("invx", "invx"),
    ("invy", "invy"),
    ("invz", "invz"),
];

/// Result fields in `tdata` order, with the core output each one comes from (`flags`: bit 0
/// is `res_hit`, bits 1–7 are 0).
pub const RES_FIELDS: [(&str, &str); 6] =
    [("id", "res_id"), ("flags", "res_hit"), ("tri", "res_tri"), ("t", "res_t"), ("u", "res_u"), ("v", "res_v")];

/// Bits of each part of a `tdata` bus: a signal holds at most 128 bits, and 64 keeps every
/// part's value an i128 in the simulator whatever its top bit.
pub const PART_BITS: u32 = 64;

impl Layout {
    /// The layout of `core`'s ports (their widths and signedness).
    pub fn of(core: &Module) -> Layout {
        let ty = |port: &str| -> Ty {
            let input = core.inputs.iter().find(|&&i| core.sig(i).name == port).map(|&i| core.sig(i).ty);
            let output = core.outputs.iter().find(|o| o.0 == port).map(|o| core.sig(o.1).ty);
            input.or(output).unwrap_or_else(|| panic!("{}: no port {port}", core.name))
        };
        let place = |fields: &[(&'static str, &str)]| -> (Vec<Field>, u32) {
            let mut offset = 0;
            let placed = fields
                .iter()
                .map(|&(name, port)| {
                    let t = if name == "flags" { Ty::u(8) } else { ty(port) };
                    let f = Field { name, offset, bytes: t.width.div_ceil(8), bits: t.width, signed: t.signed };
                    offset += f.bytes;
                    f
                })
                .collect();
            (placed, offset.next_power_of_two())
        };
        let (ray, ray_bytes) = place(&RAY_FIELDS);
        let (res, res_bytes) = place(&RES_FIELDS);
        Layout { ray, ray_bytes, res, res_bytes }
    }

    pub fn ray_field(&self, name: &str) -> &Field {
        self.ray.iter().find(|f| f.name == name).unwrap_or_else(|| panic!("no ray field {name}"))
    }
    pub fn res_field(&self, name: &str) -> &Field {
        self.res.iter().find(|f| f.name == name).unwrap_or_else(|| panic!("no result field {name}"))
    }
}

/// Bits [lo, lo + w) of the concatenation of `pieces` ((lowest bit, value), none overlapping),
/// zeros where no piece is.
fn bits_of<'b>(b: &'b Builder, pieces: &[(u32, S<'b>)], lo: u32, w: u32) -> S<'b> {
    let mut parts = Vec::new(); // least significant first
    let mut at = lo;
    while at < lo + w {
        match pieces.iter().find(|(l, s)| *l <= at && at < l + s.width()) {
            Some(&(l, s)) => {
                let take = (l + s.width()).min(lo + w) - at;
                parts.push(s.slice(at - l, take));
                at += take;
            }
            None => {
                let next = pieces.iter().map(|p| p.0).filter(|&l| l > at).min().unwrap_or(lo + w);
                let take = next.min(lo + w) - at;
                parts.push(b.konst(Ty::u(take), 0));
                at += take;
            }
        }
    }
    parts.reverse();
    if parts.len() == 1 { parts[0] } else { b.cat(&parts) }
}

/// The names of the parts of a `tdata` bus of `bytes` bytes.
pub fn part_names(bus: &str, bytes: u32) -> Vec<String> {
    (0..(bytes * 8).div_ceil(PART_BITS)).map(|k| format!("{bus}_{k}")).collect()
}

/// The core `core` (built by `top::core_module` for `p`) behind AXI4-Stream ports: module
/// `{core}_axis`.
/// Clocks the wrapper adds to the core's latency: a result leaves the core into the output
/// register, which drives `m_axis_res_*`; a ray goes into the core's port the clock it is taken.
pub const AXIS_ADDED_LATENCY: u64 = 1;

/// Rays taken whose results have not left the wrapper, at most: the core's and two in its
/// result register slice.
pub fn axis_rays_held(p: &CoreParams) -> u32 {
    p.rays_held() + 2
}

pub fn axis_module(core: &Rc<Module>, p: &CoreParams) -> Module {
    let layout = Layout::of(core);
    let b = Builder::new(&format!("{}_axis", core.name));
    let bit = Ty::BIT;
    let part = |name: &str| b.input(name, Ty::u(PART_BITS));
    let s_valid = b.input("s_axis_ray_tvalid", bit);
    let ray_parts: Vec<S> = part_names("s_axis_ray_tdata", layout.ray_bytes).iter().map(|n| part(n)).collect();
    let s_last = b.input("s_axis_ray_tlast", bit);
    let m_ready = b.input("m_axis_res_tready", bit);
    let pieces: Vec<(u32, S)> = ray_parts.iter().enumerate().map(|(k, &s)| (k as u32 * PART_BITS, s)).collect();
    // Each field from its bytes: the low `bits` bits (sign or zero extension and padding are
    // not read).
    let field = |f: &Field| {
        let x = bits_of(&b, &pieces, 8 * f.offset, f.bits).name(&format!("ray_{}", f.name));
        if f.signed { x.signed() } else { x }
    };

    // Rays taken whose results have not left. The core holds at most its port register's, its
    // slots' and its result queue's, the wrapper two more in its register slice; the count
    // has a bit more than that needs, and no ray is taken at its top, so it cannot wrap
    // whatever the core does (and never holds a ray back from a core that keeps its bound).
    let held = axis_rays_held(p);
    let count_bits = crate::scene::rom::value_bits(held as usize) + 1;
    let in_flight = b.reg("in_flight", Ty::u(count_bits), Some(0));
    let room = in_flight.ne((1i128 << count_bits) - 1).name("room");
    // A frame's last ray was taken: no ray until its results have left.
    let frame_end = b.reg("frame_end", bit, Some(0));
    let core_ready = b.wire("core_ray_ready", bit);
    let open = (!frame_end & room).name("ray_open");
    let s_ready = (core_ready & open).name("ray_tready");
    let offer = (s_valid & open).name("ray_offer");
    let take = (s_valid & s_ready).name("ray_take");

    // The result register slice: `out_*` drive the port; `skid_*` catch the result the core
    // gives in the clock the port stalls (the core's `res_ready` is `!skid_valid`, a register).
    let out_valid = b.reg("out_valid", bit, Some(0));
    let skid_valid = b.reg("skid_valid", bit, Some(0));
    let res_ready = (!skid_valid).name("core_res_ready");

    let mut ins: Vec<S> = Vec::new();
    for &i in &core.inputs {
        let port = core.sig(i).name.as_str();
        ins.push(match port {
            "ray_valid" => offer,
            "res_ready" => res_ready,
            // An external-memory core's read port and base address, passed through.
            _ if super::top_memory::is_memory_port(port) => b.input(port, core.sig(i).ty),
            _ => match RAY_FIELDS.iter().find(|f| f.1 == port) {
                Some(&(name, _)) => field(layout.ray_field(name)),
                None => panic!("{}: the AXI4-Stream wrapper does not know input {port}", core.name),
            },
        });
    }
    let c = b.instance("u_core", core, &ins);
    b.drive(core_ready, c.get("ray_ready"));
    let res_in = (c.get("res_valid") & res_ready).name("res_take");
    let out_free = (!out_valid | m_ready).name("out_free");
    let out_take = (out_valid & m_ready).name("res_out_take");
    b.next(out_valid, out_free.select(skid_valid | res_in, out_valid));
    b.next(skid_valid, out_free.select(skid_valid.k(0), skid_valid | res_in));
    let mut out_fields: Vec<(u32, S)> = Vec::new();
    for f in &layout.res {
        let port = RES_FIELDS.iter().find(|x| x.0 == f.name).expect("a result field").1;
        let x = c.get(port);
        let skid = b.reg(&format!("skid_{}", f.name), x.ty(), None);
        b.next_when(skid, res_ready, x);
        let out = b.reg(&format!("out_{}", f.name), x.ty(), None);
        b.next_when(out, out_free, skid_valid.select(skid, x));
        // Sign- or zero-extended to the field's bytes.
        out_fields.push((8 * f.offset, out.resize(8 * f.bytes)));
    }

    // The count and the barrier: the last ray of a frame is the only one undelivered when the
    // count is 1 after the frame ended, so the result at the port then is the frame's last.
    let plus = take.select(in_flight + 1, in_flight);
    b.next(in_flight, out_take.select(plus - 1, plus));
    let last_out = (frame_end & in_flight.eq(1)).name("frame_last");
    b.next(frame_end, frame_end.select(!(out_take & last_out), take & s_last));

    b.output("s_axis_ray_tready", s_ready);
    b.output("m_axis_res_tvalid", out_valid);
    let res_names = part_names("m_axis_res_tdata", layout.res_bytes);
    let used = 8 * layout.res.iter().map(|f| f.bytes).sum::<u32>();
    for (k, name) in res_names.iter().enumerate() {
        let (lo, label) = (k as u32 * PART_BITS, format!("res_tdata_{k}"));
        let bits = if lo >= used {
            b.konst_named(&label, Ty::u(PART_BITS), 0) // padding only
        } else {
            bits_of(&b, &out_fields, lo, PART_BITS).name(&label)
        };
        b.output(name, bits);
    }
    b.output("m_axis_res_tlast", (out_valid & last_out).name("res_tlast"));
    for (port, _) in core.outputs.iter().filter(|o| super::top_memory::is_memory_port(&o.0)) {
        b.output(port, c.get(port));
    }
    let ray_names = part_names("s_axis_ray_tdata", layout.ray_bytes);
    b.with(|m| {
        m.bus("s_axis_ray_tdata", &ray_names.iter().map(String::as_str).collect::<Vec<_>>());
        m.bus("m_axis_res_tdata", &res_names.iter().map(String::as_str).collect::<Vec<_>>());
        // What integrators instantiate: std_logic / std_logic_vector ports in VHDL.
        m.std_ports = true;
    });
    b.finish()
}
