//! The traversal unit's plane-distance unit (golden twin `Golden::plane_t`):
//! ((P − O_axis) · inv_axis) >> C, clamped to [−1, 2^(n+1)], pipelined so that every
//! register-to-register path holds one mux level and one adder, or the multiplier alone.
//!
//! Stages, one clock each; a distance issued in cycle c is on `t` in cycle c + `latency`:
//! 1. select: the issuing state's plane (n bits) and axis (2 bits), with a valid and a last
//!    bit. The traversal builds the select so that a node ROM field passes one mux level at
//!    most before this register.
//! 2. delta: P − O_axis (n + 1 bits, signed) and inv_axis (m + C bits) — the axis mux and one
//!    subtractor.
//! 3. product: `plane_product`, its own number of stages (the clock target's `MulStyle`: 1
//!    for one multiplier between two registers, more for DSP pieces and an adder tree).
//! 4. clamp: the shift by C (wiring) and the clamp to [−1, 2^(n+1)] (the sign bit, one bit
//!    reduction and a mux), registered. With a split product (a fast clock target) it takes
//!    two clocks: the reduction is registered beside the distance's bits (4a, by the product,
//!    which sits by the DSP blocks), and the mux (4b) is one LUT before the distance registers
//!    (by their users): the route across the die between gets a clock of its own.
//!
//! The valid and last bits ride along in shift registers of the same depth, so a state
//! machine waits for results by their valid bit and never counts the latency itself: a
//! deeper multiplier changes `latency`, not the machine.

use super::mul::{MulStyle, latency, product_core};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};
use std::rc::Rc;

/// The product delta · inv (n + 1 by m + C bits, signed, full width) and its latency in
/// clocks, built as the clock target's `MulStyle` says (`cores::mul`): one multiplier
/// between two registers when combinational (latency 1), else DSP-sized pieces with their
/// registers and a registered adder tree.
pub fn plane_product<'b>(b: &'b Builder, delta: S<'b>, inv: S<'b>, style: MulStyle) -> (S<'b>, u32) {
    if !style.split() {
        return (b.delay("pu_product", delta.xmul(inv).name("pu_mul")), 1);
    }
    let m = Rc::new(product_core(delta.ty(), inv.ty(), style));
    (b.instance("u_plane_product", &m, &[delta, inv]).get("p").name("pu_product"), latency(delta.ty(), inv.ty(), style))
}

/// The reciprocal direction on `axis`. Split (a spread core's landed products): picked in
/// groups of `PICK_BITS` bits, each by a copy of the axis register of its own. The one axis
/// register (merged by yosys with the traversal's `axis_n1`) fanning out to both units' picks
/// into the DSP pieces' operand registers was a slowest path of the fitted core at seed 1
/// (7.08 ns, 22 endpoints over 6.67).
fn pick_inv<'b>(b: &'b Builder, axis: S<'b>, inv: [S<'b>; 3], split: bool) -> S<'b> {
    let w = inv[0].width();
    if !split || w <= PICK_BITS {
        return b.pick(axis, inv);
    }
    let groups = w.div_ceil(PICK_BITS);
    let sels = b.copies(axis, groups as usize);
    let parts: Vec<S<'b>> = (0..groups)
        .rev()
        .map(|g| {
            let (lsb, width) = (g * PICK_BITS, PICK_BITS.min(w - g * PICK_BITS));
            b.pick(sels[g as usize], inv.map(|x| x.slice(lsb, width)))
        })
        .collect();
    b.cat(&parts).signed()
}

/// The widest group of bits `pick_inv` selects by one register.
const PICK_BITS: u32 = 16;

/// What a state issues to the unit in a cycle: combinational signals, registered by stage 1.
pub struct PlaneIssue<'b> {
    /// A distance is issued this cycle.
    pub valid: S<'b>,
    /// It is the last of a group (d1 of an inner node, the third axis of the scene box).
    pub last: S<'b>,
    /// The plane, n bits unsigned.
    pub plane: S<'b>,
    /// The axis, 2 bits (3 never occurs).
    pub axis: S<'b>,
}

/// The unit's result: registered, `latency` clocks after the issue.
pub struct PlaneResult<'b> {
    /// The clamped distance, signed n + 3 bits.
    pub t: S<'b>,
    /// `t` when `last` is 1 (the same register value then), held otherwise.
    pub t_last: S<'b>,
    /// `t` when it is valid and `last` is 0 (a group's first distance: d0 of an inner node),
    /// held otherwise: d0 until the next node's d0, the cycle d1 arrives included.
    pub t_first: S<'b>,
    pub valid: S<'b>,
    pub last: S<'b>,
    pub latency: u32,
}

/// The unit for a ray whose origin `o` (n bits each) and reciprocal direction `inv` (m + C
/// bits, signed) stay in their registers while distances are issued; `product` is the style
/// `plane_product` builds.
pub fn plane_unit<'b>(
    b: &'b Builder,
    n: u32,
    c: u32,
    o: [S<'b>; 3],
    inv: [S<'b>; 3],
    issue: PlaneIssue<'b>,
    product: MulStyle,
) -> PlaneResult<'b> {
    // 1. select
    let valid = b.valid_delay("pu_sel_valid", issue.valid);
    let last = b.delay("pu_sel_last", issue.last);
    let plane = b.delay("pu_sel_plane", issue.plane);
    let axis = b.delay("pu_sel_axis", issue.axis);
    // 2. delta: P − O never leaves ±(2^n − 1), so n + 1 signed bits hold it.
    let delta = b.delay("pu_delta", (plane.xsigned() - b.pick(axis, o).xsigned()).name("pu_diff"));
    let inv_a = b.delay("pu_inv", pick_inv(b, axis, inv, product.is_landed()).name("pu_inv_axis"));
    let (valid, last) = (b.valid_delay("pu_delta_valid", valid), b.delay("pu_delta_last", last));
    // 3. product
    let product_style = product;
    let (product, product_latency) = plane_product(b, delta, inv_a, product);
    let valid = b.valid_line("pu_product_valid", valid, product_latency);
    let last = b.delay_line("pu_product_last", last, product_latency);
    // 4. clamp. The two range tests are bit reductions, not compares with constants: yosys
    // builds those as two carry chains of the shifted product's full width (62 bits by
    // default), and with the select they made a 9 ns stage. With s = product >> C, the clamp
    // to [−1, 2^(n+1)] is: s negative → −1 (s = −1 is −1 either way), s ≥ 2^(n+1) → 2^(n+1)
    // (s = 2^(n+1) is that either way): the sign bit and one OR over the bits from n + 1 up.
    // (Testing s < −1 and s > 2^(n+1) exactly took two more reductions, over all of s and its
    // low n + 1 bits: the stage made the whole core's critical path, 7.5–8.6 ns, 5.4–7.1 ns of
    // it routing from the DSP column.)
    // With a split product, 4a registers the tests and the n + 3 low bits (which hold s when
    // neither test holds) by the product, and 4b muxes them by the users (in the whole Cornell
    // core, the one-clock clamp spent 6.6 ns of 8.1 routing from the product's register at the
    // die's edge to the distance registers in its middle).
    let w = product.width() - c;
    let shifted = product.slice(c, w).signed().name("pu_shifted");
    let k = n + 1;
    let below = shifted.msb().name("pu_below");
    let above = (!below & shifted.slice(k, w - 1 - k).ne(0)).name("pu_above");
    let dist_w = Ty::s(n + 3).width;
    let low = shifted.resize(dist_w);
    let split = product_style.split();
    let (above, below, low, valid, last) = if split {
        (
            b.delay("pu_above_r", above),
            b.delay("pu_below_r", below),
            b.delay("pu_low_r", low),
            b.valid_delay("pu_clamp_valid", valid),
            b.delay("pu_clamp_last", last),
        )
    } else {
        (above, below, low, valid, last)
    };
    let t_sat = low.k(1i128 << k);
    let clamped = above.select(t_sat, below.select(low.k(-1), low)).name("pu_clamped");
    let t = b.delay("plane_t", clamped);
    // The same distance in a register that loads only with a group's last one: a copy for the
    // traversal's decision compares, so `t` does not fan out to every compare (yosys merges two
    // equal registers, not two with different enables).
    let t_last = b.reg("plane_t_of_last", t.ty(), None);
    b.next_when(t_last, last, clamped);
    // And one for the first distance of a group (d0), which holds it while d1 arrives: the
    // traversal compares d0 from it the cycle it arrives, so its results are registered when d1
    // comes (a third load enable, so yosys keeps the three apart).
    let t_first = b.reg("plane_t_of_first", t.ty(), None);
    b.next_when(t_first, (valid & !last).name("pu_first"), clamped);
    PlaneResult {
        t,
        t_last,
        t_first,
        valid: b.valid_delay("plane_t_valid", valid),
        last: b.delay("plane_t_last", last),
        latency: 3 + product_latency + split as u32,
    }
}
