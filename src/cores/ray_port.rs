//! The core's ray port and its box-exit unit (`top.rs` builds the rest around them).
//!
//! A ray waits in the port's register until the box-exit unit is idle (it takes one ray per 4
//! clocks: it issues the three exit distances of the scene box to a plane unit of its own and
//! the unit reads the ray a clock after the last issue) and the traversal unit whose turn it is
//! has a free slot. A clock after the take the ray is written into that slot (`accept`); its
//! box exit follows through the unit's new-ray queue when the plane unit has it.

use super::core_params::CoreParams;
use super::lt_chain;
use super::plane::{PlaneIssue, plane_unit};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// Whether global slot number `slot` belongs to unit `u` (unit bits above `sb` slot bits).
pub fn is_unit(slot: S<'_>, u: u32, sb: u32, ub: u32) -> S<'_> {
    if ub == 0 { slot.k(0).resize(1).eq(0) } else { slot.slice(sb, ub).eq(u as i128) }
}

/// The ray port, as the rest of the core sees it.
pub struct RayPort<'b> {
    /// `ray_ready`: the port's register is empty (a register).
    pub ready: S<'b>,
    /// The take: the box-exit unit's phase (0: idle), the ray's global slot, and the ray's
    /// origin and reciprocal direction held for the box-exit unit.
    pub take: S<'b>,
    pub take_slot: S<'b>,
    pub phase: S<'b>,
    pub box_o: [S<'b>; 3],
    pub box_inv: [S<'b>; 3],
    /// A clock after the take: `accept` and the ray's slot (`slot` global; `closest_slot` a
    /// copy for the closest-hit unit's id RAM) and id; each unit's `alloc` (the last of
    /// `unit_we[u]`). A clock later the ray (origin, direction and reciprocal direction, still
    /// in `o`, `w`, `inv`) is written into its slot's RAMs, from registers of their own for the
    /// write enables and addresses of the RAMs it reaches (a LUT-RAM slice per 4 bits and 16
    /// slots each, 888 sinks a bit from one register on the teapot-fine core): `ram_slots`
    /// the leaf streams' ray RAMs (lane by lane, a register per group of columns, `wide_ram`,
    /// with `ram_we` the write enables alike), `unit_slot[u]` unit u's (within the unit: one
    /// per group of its ray RAMs' columns), and `unit_we[u]` unit u's write enables alike.
    pub accept: S<'b>,
    pub slot: S<'b>,
    pub ram_we: Vec<S<'b>>,
    pub ram_slots: Vec<S<'b>>,
    pub closest_slot: S<'b>,
    pub unit_slot: Vec<Vec<S<'b>>>,
    pub unit_we: Vec<Vec<S<'b>>>,
    pub id: S<'b>,
    pub o: [S<'b>; 3],
    pub w: [S<'b>; 3],
    pub inv: [S<'b>; 3],
    /// Each unit's `has_free` and `free_slot_out`: wires, driven when the units are made.
    pub unit_has_free: Vec<S<'b>>,
    pub unit_free_slot: Vec<S<'b>>,
}

/// The port's register, the turn among the units and the take; `ins` are the ray inputs in
/// `top::core_inputs` order.
pub fn ray_port<'b>(b: &'b Builder, p: &CoreParams, ins: &[S<'b>]) -> RayPort<'b> {
    let [ray_valid, ray_id, ox, oy, oz, wx, wy, wz, ix, iy, iz] = ins[..] else { unreachable!("11 ray ports") };
    let (units, sb, ub, bit) = (p.units, p.trav.slot_bits(), p.unit_bits(), Ty::BIT);
    b.stage("ray_port", "the ray port's register, the unit whose turn it is, the take (a ray per 4 clocks)");
    // Wires from the units (driven once they are instantiated).
    let has_free_w: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_has_free"), bit)).collect();
    let free_idx_w: Vec<S> = (0..units).map(|u| b.wire(&format!("u{u}_free_slot"), Ty::u(sb))).collect();

    // Acceptance: into the unit whose turn it is (`turn` moves on with every ray and every
    // clock that unit is full).
    let turn = b.reg("turn", Ty::u(ub.max(1)), Some(0));
    let phase = b.reg("box_phase", Ty::u(2), Some(0));
    // The units' free-slot outputs in registers of the top's own (the units sit across the die):
    // a clock staler still, which the 4-clock cadence covers (a unit masks a slot it gave for a
    // clock, and the next ray comes 4 clocks later).
    // Reset as the units' registers are (all free, slot 0), so idling after reset changes nothing.
    let copy = |name: String, x: S<'b>, reset: i128| {
        let r = b.reg(&name, x.ty(), Some(reset));
        b.next(r, x);
        r
    };
    let free_idx: Vec<S> =
        free_idx_w.iter().enumerate().map(|(u, &x)| copy(format!("u{u}_free_slot_r"), x, 0)).collect();
    // Whether the unit whose turn it is has a free slot, as one register: chosen by the next
    // turn among the units' outputs (what copies of them would hold next clock), it equals the
    // choice by `turn` among such copies, so the take — which loads every port register, a net
    // across the die — depends on three registers through one LUT (with four units the choice
    // after the copies cost 9.6 ns: 103.8 MHz).
    let turn_free = b.reg("turn_free", bit, Some(1));
    let turn_slot = if units == 1 {
        free_idx[0]
    } else {
        b.case(turn, &(0..units).map(|u| (u as u128, free_idx[u as usize])).collect::<Vec<_>>(), free_idx[0])
    };
    // The ray port's register: a ray waits in it for the box-exit unit and a slot. The port is
    // ready when the register is empty: a register, so the load enable of the port's ~300
    // flip-flops is a net from flip-flops (ready also when the ray is taken that clock put the
    // take's logic before that net: 9.4 ns at seed 1 of the default core). It costs no ray:
    // after a take the box-exit unit is busy for 4 clocks, and the register is full again 2
    // clocks after the take.
    let in_valid = b.reg("in_valid", bit, Some(0));
    let port_empty = b.reg("port_empty", bit, Some(1));
    // Whether the box-exit unit is idle (phase 0), as registers of its own: one for the take,
    // one for the box-exit operands' ~180 load enables. The phase register drove both, so it
    // sat among the operands, and the take's path from it to `port_empty` was the default
    // core's third slowest at seed 1 (8.01 ns, 4 cells).
    let idle = b.reg("box_idle", bit, Some(1));
    let take = (in_valid & idle & turn_free).name("take");
    let in_valid_next = (port_empty & ray_valid) | (in_valid & !take);
    b.next(in_valid, in_valid_next);
    b.next(port_empty, !in_valid_next);
    // Four registers of it, each loading a part of the port.
    let empties: Vec<S<'b>> = [port_empty].into_iter().chain(b.copies(port_empty, 3)).collect();
    let mut holds = 0usize;
    let hold = |s: S<'b>| {
        let r = b.reg(&format!("in_{}", b.name_of(s.sig)), s.ty(), None);
        b.next_when(r, empties[holds * empties.len() / 10], s);
        holds += 1;
        r
    };
    let [in_id, ox, oy, oz, wx, wy, wz, ix, iy, iz] = [ray_id, ox, oy, oz, wx, wy, wz, ix, iy, iz].map(hold);
    let take_slot = if ub == 0 { turn_slot } else { b.cat(&[turn.resize(ub), turn_slot]) }.name("take_slot");
    let next_turn = (turn + 1).name("turn_plus_1");
    let next_turn =
        if units.is_power_of_two() { next_turn } else { next_turn.eq(units as i128).select(turn.k(0), next_turn) };
    let turn_next = (take | !turn_free).select(next_turn, turn).name("turn_next");
    b.next(turn, turn_next);
    let pick = |u: u32| (u as u128, has_free_w[u as usize]);
    let has_free_at = |t: S<'b>| b.case(t, &(0..units).map(pick).collect::<Vec<_>>(), b.konst(bit, 0));
    b.next(
        turn_free,
        if units == 1 {
            has_free_w[0]
        } else if p.isect.spread {
            // Both choices made from registers, the take picking one: through `turn_next` the
            // loop `turn_free` → take → `turn_free` was a slowest path of the fitted core at
            // seed 1 (7.01 ns).
            let moves = (take | !turn_free).name("turn_moves");
            moves.select(has_free_at(next_turn), has_free_at(turn)).name("turn_free_next")
        } else {
            has_free_at(turn_next)
        },
    );
    let phase_next = (take | phase.ne(0)).select(phase + 1, phase).name("box_phase_next");
    b.next(phase, phase_next);
    b.next(idle, phase_next.eq(0).name("box_idle_next"));
    let idle_load = b.copies(idle, 1)[0];
    // The box-exit unit's operands load whenever it is idle: when a ray is taken they hold it.
    let box_reg = |s: S<'b>| {
        let r = b.reg(&format!("box_{}", b.name_of(s.sig)), s.ty(), None);
        b.next_when(r, idle_load, s);
        r
    };
    let box_o = [ox, oy, oz].map(box_reg);
    let box_inv = [ix, iy, iz].map(box_reg);
    // The taken ray is written into the slot's RAMs a clock later, from registers of its own:
    // `accept` drives the write enables of every ray RAM and the units' free bits, far across
    // the die, so it leaves a register rather than the take decision's logic. The slot still
    // reads as taken at the next take (4 clocks later at the earliest): the unit sees `alloc` a
    // clock after the take and masks its free output the clock after (`just_alloc`), which the
    // top's copies show 3 clocks after the take; a clock after that they show the new lowest
    // free slot. (One clock more would still be safe, two would give a slot twice: the
    // visit-order test fails then.)
    let accept = b.valid_delay("accept", take);
    let gslot = b.delay("accept_slot", take_slot);
    // The ray RAMs are written a clock later still, from a tree: the take loaded every RAM
    // group's write-enable register across the die, and `turn_free` → `accept` through it was
    // a slowest path at seeds 2 and 3 (6.84, 6.92 ns, two cells). Now the take loads `accept`,
    // the closest-hit unit's id write and each unit's `alloc`, and `accept` the write enables.
    // The data still holds the taken ray then: the port reloads two clocks after a take at
    // the earliest, and `acc_*` read it a clock late. No ray RAM entry is read that early (the
    // box-exit unit takes 4 clocks and more).
    let write = b.valid_delay("accept_w", accept);
    let wslot = b.delay("accept_w_slot", gslot);
    // One write enable fanned out to all the ray RAMs' cells was a slowest path at seed 2
    // (`accept` → `ray_w`, 7.82 ns, eight such).
    let ram_groups = p.ray_ram_groups() * p.pipelines as usize;
    let ram_we = super::wide_ram::address_registers(b, write, ram_groups);
    let unit_groups = p.trav.ray_ram_groups();
    let copies = b.copies(wslot, ram_groups - 1 + units as usize * unit_groups);
    let ram_slots: Vec<S<'b>> = std::iter::once(wslot).chain(copies[..ram_groups - 1].iter().copied()).collect();
    // A unit's write enables are the take for that unit, registered twice (its `alloc`, the
    // last, once): `accept` and a select of the slot's unit bits after it reached every cell of
    // the unit's ray RAMs and its free list.
    let unit_we = (0..units)
        .map(|u| {
            let mine = (take & is_unit(take_slot, u, sb, ub)).name(&format!("u{u}_take"));
            let alloc = b.valid_delay(&format!("u{u}_accept"), mine);
            let write = b.valid_delay(&format!("u{u}_accept_w"), alloc);
            let mut wes = super::wide_ram::address_registers(b, write, unit_groups);
            wes.push(alloc);
            wes
        })
        .collect();
    let [id, ox, oy, oz, wx, wy, wz, ix, iy, iz] =
        [in_id, ox, oy, oz, wx, wy, wz, ix, iy, iz].map(|s| b.delay(&format!("acc_{}", b.name_of(s.sig)), s));
    RayPort {
        ready: port_empty,
        take,
        take_slot,
        phase,
        box_o,
        box_inv,
        accept,
        slot: gslot,
        ram_we,
        ram_slots,
        closest_slot: b.copies(gslot, 1)[0],
        unit_slot: copies[ram_groups - 1..]
            .chunks(unit_groups)
            .map(|c| c.iter().map(|c| c.slice(0, sb)).collect())
            .collect(),
        unit_we,
        id,
        o: [ox, oy, oz],
        w: [wx, wy, wz],
        inv: [ix, iy, iz],
        unit_has_free: has_free_w,
        unit_free_slot: free_idx_w,
    }
}

/// The box-exit unit's result: the ray's scene-box exit distance, for its unit's new-ray queue.
pub struct BoxExit<'b> {
    pub done: S<'b>,
    /// The ray's global slot.
    pub slot: S<'b>,
    pub tmax: S<'b>,
    /// The ray misses the scene box (an exit distance is negative).
    pub miss: S<'b>,
}

/// The box-exit unit: the three exit planes' distances from a plane unit of its own, and the
/// smallest of them.
pub fn box_exit<'b>(b: &'b Builder, p: &CoreParams, port: &RayPort<'b>) -> BoxExit<'b> {
    let (n, gb, phase) = (p.isect.n, p.tag.slot_bits, port.phase);
    b.stage("box_exit", "the scene-box exit distance: three plane distances, the smallest");
    let box_slot = b.reg("box_slot", Ty::u(gb), None);
    b.next_when(box_slot, port.take, port.take_slot);
    let axis = (phase - 1).name("box_axis");
    let hi = [0, 1, 2].map(|k| b.konst_named(&format!("box_hi_{k}"), Ty::u(n), p.trav.box_hi[k] as i128));
    let neg = b.pick(axis, port.box_inv).msb().name("box_neg");
    let issue = PlaneIssue {
        valid: phase.ne(0).name("box_issue"),
        last: phase.eq(3).name("box_issue_last"),
        plane: neg.select(hi[0].k(0), b.pick(axis, hi)).name("box_plane"),
        axis,
    };
    let pu = plane_unit(b, n, p.trav.c, port.box_o, port.box_inv, issue, p.trav.product);
    let plane_t = pu.t;
    let box_d1 = b.delay("box_d1", plane_t);
    let box_d2 = b.delay("box_d2", box_d1);
    let box_d3 = b.delay("box_d3", box_d2);
    let box_lt1 = b.delay("box_lt1", lt_chain(plane_t, box_d1).name("box_lt1_c"));
    let box_lt2 = b.delay("box_lt2", lt_chain(plane_t, box_d2).name("box_lt2_c"));
    let box_lt1_d = b.delay("box_lt1_d", box_lt1);
    let tmax = (box_lt1 & box_lt2).select(box_d1, box_lt1_d.select(box_d2, box_d3)).name("box_tmax");
    let miss = (box_d1.msb() | box_d2.msb() | box_d3.msb()).name("box_miss");
    let done = b.valid_delay("box_done", (pu.valid & pu.last).name("box_last"));
    let slot = b.delay_line("box_done_slot", box_slot, pu.latency + 1);
    BoxExit { done, slot, tmax, miss }
}
