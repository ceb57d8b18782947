//! The closest-hit unit: watches the intersection pipeline's output stream and keeps, for every
//! ray slot of the core, the smallest (t, triangle number) among accepted hits — a hit is
//! accepted only if t ≥ lower_t(leaf entry distance) (`golden::lower_t`).
//!
//! The leaf stream sends a leaf's triangles one after another (the arbiter switches between
//! traversal units only between leaves), tagged with the ray's slot and flags for a leaf's first
//! and last triangle. So one accumulator keeps the best of the leaf in flight; after its last
//! triangle it is **merged** into the slot's best hit (a RAM indexed by slot, with a valid bit
//! per slot), and the merge is reported back to the slot's traversal unit with the slot's new
//! best t + 8 (the cull limit) and its stack pointer, which unparks the ray. A slot has at most
//! one leaf in flight, so a merge never races another one for the same slot.
//!
//! When a ray's walk is done (`done_*`, from the traversal units' done queues), its best hit is
//! read and sent out with the ray id (results leave in the order rays finish), the slot's valid
//! bit is cleared and the slot is reported free.
//!
//! The pipeline tag, from bit 0: triangle number, leaf entry distance (n + 2 bits), the ray's
//! stack pointer, its slot, then the leaf's first and last flags.

use super::clock::ClockTarget;
use super::wide_ram::WideRam;
use super::{lt_chain, slot_bit_2, slot_bit_groups};
use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};

#[derive(Clone, Copy, Debug)]
pub struct TagLayout {
    pub tri_bits: u32,
    pub tmin_bits: u32,
    pub sp_bits: u32,
    pub slot_bits: u32,
}

impl TagLayout {
    pub fn width(&self) -> u32 {
        self.tri_bits + self.tmin_bits + self.sp_bits + self.slot_bits + 2
    }
}

/// Whether the closest-hit unit registers its input stream (and the acceptance test) before
/// comparing with the best hit: from this clock target up (`ClockTarget::splits`).
pub const STAGED_FROM_MHZ: u32 = 126;

/// Cycles from a pipeline result to the unit's accumulator: 2 when staged for the target.
pub fn input_latency(target: ClockTarget) -> u32 {
    2 * target.splits(STAGED_FROM_MHZ) as u32
}

/// The unit of one lane (intersection pipeline) of the core: `slots` slot numbers, `units`
/// traversal units, `unit_bits` their numbers' bits, and `lane_bits` bits of the lane number
/// above them in the tag's global slot (0 with one pipeline), which the unit drops: its RAMs
/// and ports take the slot number within the lane.
/// Ports: valid, tag, hit, t (n + 1 bits), u, v (m bits) from the pipeline; `id_we`, `id_slot`,
/// `id` (a ray's id, written when its slot is taken); `done_valid`, `done_slot`,
/// `done_slot_copies` (`slot_bit_groups(slots)` copies of it, the first lowest) →
/// per traversal unit u `merge_valid{u}`, `merge_slot{u}` (the slot within the unit: the global
/// slot's low bits below the `unit_bits` unit number), `merge_hit{u}`, and for all of them
/// `merge_limit` (best t + 8, signed n + 3 bits), `merge_sp`; `free_valid`, `free_slot`; res_valid, res_id, res_hit, res_tri, res_t, res_u, res_v
/// (t, u, v and tri read 0 for a miss), registered, three cycles after `done_valid`.
#[allow(clippy::too_many_arguments)]
pub fn closest_core(
    tag: TagLayout,
    slots: u32,
    [units, unit_bits, lane_bits]: [u32; 3],
    id_bits: u32,
    n: u32,
    m_bits: u32,
    target: ClockTarget,
) -> Module {
    let staged = input_latency(target) > 0;
    let suffix = if staged { "_r2" } else { "" };
    let lanes = if lane_bits > 0 { format!("_l{}", 1 << lane_bits) } else { String::new() };
    let b = Builder::new(&format!("fxrt_closest_n{n}_m{m_bits}_tag{}_s{slots}_u{units}{lanes}{suffix}", tag.width()));
    let valid = b.input("valid", Ty::BIT);
    let tag_in = b.input("tag", Ty::u(tag.width()));
    let hit = b.input("hit", Ty::BIT);
    let t = b.input("t", Ty::u(n + 1));
    let u = b.input("u", Ty::u(m_bits));
    let v = b.input("v", Ty::u(m_bits));
    let slot_ty = Ty::u(tag.slot_bits - lane_bits);
    let id_we = b.input("id_we", Ty::BIT);
    let id_slot = b.input("id_slot", slot_ty);
    let id_in = b.input("id", Ty::u(id_bits));
    let done_valid = b.input("done_valid", Ty::BIT);
    let done_slot = b.input("done_slot", slot_ty);
    // Copies of `done_slot` (registers of their own in the top), one per group of 16 slots'
    // has-best bits.
    let groups = slot_bit_groups(slots);
    let done_slot_c = b.input("done_slot_copies", Ty::u(groups * slot_ty.width));
    let done_slots: Vec<S> = (0..groups).map(|g| done_slot_c.slice(g * slot_ty.width, slot_ty.width)).collect();
    let mut at = 0;
    let mut take = |w: u32| {
        let s = tag_in.slice(at, w);
        at += w;
        s
    };
    let tri = take(tag.tri_bits).name("tri");
    let tmin = take(tag.tmin_bits).name("tmin");
    let sp = take(tag.sp_bits).name("sp");
    let slot = take(tag.slot_bits).slice(0, tag.slot_bits - lane_bits).name("slot");
    let first = take(1).name("first");
    let last = take(1).name("last");

    // lower_t(tmin) = tmin − tmin/64 − 8, and t, both signed n + 3 bits. A hit is accepted
    // when t + 8 ≥ tmin − tmin/64: two subtractions side by side, then one comparison, rather
    // than three carry chains in series.
    let dist = n + 3;
    let tmin_d = tmin.xsigned().resize(dist);
    let x = (tmin_d - (tmin_d >> 6)).name("tmin_less");
    let t8 = (t.xsigned().resize(dist) + 8).name("t_plus_8");
    // Staged: two register levels, (x, t + 8) and then the acceptance bit, so the
    // accumulator's compare starts from registers (a result arrives two cycles later;
    // nothing else changes).
    let reg = |name: &str, x, k: u32| if staged { b.delay_line(&format!("in_{name}"), x, k) } else { x };
    let vreg = |name: &str, x, k: u32| if staged { b.valid_line(&format!("in_{name}"), x, k) } else { x };
    let (x, t8) = (reg("tmin_less", x, 1), reg("t_plus_8", t8, 1));
    let (valid1, hit1) = (vreg("valid", valid, 1), reg("hit", hit, 1));
    let accepted = (!lt_chain(t8, x)).name("accepted");
    // Held inverted, the accumulator's compare taking it as its top bit (below); staged, its
    // register resets to 1 (no candidate).
    let no_candidate = (!(valid1 & hit1 & accepted)).name("no_candidate_c");
    let no_candidate = if staged {
        let r = b.reg("in_no_candidate", Ty::BIT, Some(1));
        b.next(r, no_candidate);
        r
    } else {
        no_candidate
    };
    let (valid, first, last) = (vreg("valid2", valid, 2), reg("first", first, 2), reg("last", last, 2));
    let (tri, slot, sp) = (reg("tri", tri, 2), reg("slot", slot, 2), reg("sp", sp, 2));
    let (t, u, v) = (reg("t", t, 2), reg("u", u, 2), reg("v", v, 2));

    // The best accepted hit of the leaf in flight. Closer means (t, tri) < (best_t, best_tri)
    // in lexicographic order (equal t: the smaller triangle number wins), one unsigned compare
    // of the concatenations whose last sum bit is `take` (`lt_chain`): (¬candidate, 0, t, tri)
    // < (0, empty, acc_t, acc_tri), where a leaf's first triangle sees an empty accumulator.
    let acc_empty = b.reg("acc_empty", Ty::BIT, Some(1));
    let acc_t = b.reg("acc_t", t.ty(), None);
    let acc_tri = b.reg("acc_tri", tri.ty(), None);
    let acc_u = b.reg("acc_u", u.ty(), None);
    let acc_v = b.reg("acc_v", v.ty(), None);
    let zero = b.konst(Ty::BIT, 0);
    let empty = (first | acc_empty).name("acc_empty_now");
    let take = lt_chain(b.cat(&[no_candidate, zero, t, tri]), b.cat(&[zero, empty, acc_t, acc_tri])).name("take");
    b.next_when(acc_t, take, t);
    b.next_when(acc_tri, take, tri);
    // (u, v) follow a clock later, from the registered decision and a registered copy of the
    // candidate's: `take` loading all 107 accumulator bits was the default core's fifth
    // slowest path at seed 1 (7.72 ns, 84 endpoints over 6.67 ns), and a second carry chain
    // for them was slower still at another seed (9.56 ns). The merge reads the (u, v) the
    // accumulator is about to hold (`acc_u_v_now`), the same word.
    let take_r = b.delay("take_r", take);
    let (u_r, v_r) = (b.delay("cand_u", u), b.delay("cand_v", v));
    b.next_when(acc_u, take_r, u_r);
    b.next_when(acc_v, take_r, v_r);
    let acc_uv_now = take_r.select(b.cat(&[u_r, v_r]), b.cat(&[acc_u, acc_v])).name("acc_u_v_now");
    // Empty after this clock unless a candidate came (a candidate into an empty accumulator is
    // taken; one into a full accumulator leaves it full): the same as clearing on `take`,
    // without the compare's carry chain on the path (10.6 ns at a seed of the external core).
    let stays_empty = (valid & first) | acc_empty;
    b.next(acc_empty, no_candidate.select(stays_empty, acc_empty.k(0)));

    // The slots' best hits: (t, tri) and (u, v) RAMs and a valid bit per slot.
    let k = slots;
    // In groups of LUT-RAM columns, each read and written at an address register of its own
    // (`wide_ram`): one register per RAM reaching all its cells made the done read a slowest
    // path at seed 2 (`d0_slot_c1` → `done_t_tri`, 7.39 ns).
    let tt_mem = WideRam::new(&b, "best_t_tri", t.width() + tri.width(), k as usize);
    let uv_mem = WideRam::new(&b, "best_u_v", 2 * m_bits, k as usize);
    let spread = super::clock::spread(units << lane_bits, target);
    let id_mem = if spread {
        let id_mem = WideRam::new(&b, "ray_ids", id_bits, k as usize);
        // The id lands in registers of its own here, one write enable and address per group
        // of columns, and is written a clock later: the top's `accept` through the lane select
        // and the write-enable decode into every cell was a slowest path of the fitted core at
        // seed 1 (7.18 ns, 20 groups of endpoints over 6.67). The id is read when the ray is
        // done, many clocks later.
        let we = super::wide_ram::address_registers(&b, b.valid_delay("id_we_r", id_we), id_mem.groups());
        let at = super::wide_ram::address_registers(&b, b.delay("id_slot_r", id_slot), id_mem.groups());
        id_mem.write(&b, &we, &at, b.delay("id_r", id_in));
        id_mem
    } else {
        let id_mem = WideRam::whole(&b, "ray_ids", id_bits, k as usize);
        id_mem.write(&b, &[id_we], &[id_slot], id_in);
        id_mem
    };
    let best_valid = b.reg("best_valid", Ty::u(k), Some(0));

    // The merge: fin (the cycle after a leaf's last triangle: the accumulator is final), M1
    // (the leaf's best and the slot's, read at fin's address one clock before), M2 (the
    // compare's result: report the merge), M3 (write the slot's best).
    let fin = b.valid_delay("fin", (valid & last).name("leaf_last"));
    let fin_slot = b.delay("fin_slot", slot);
    let fin_sp = b.delay("fin_sp", sp);
    let st_tt = tt_mem.read(&b, "slot_t_tri", &b.copies(fin_slot, tt_mem.groups()));
    let m1 = b.valid_delay("m1", fin);
    let m1_slot = b.delay("m1_slot", fin_slot);
    let m1_sp = b.delay("m1_sp", fin_sp);
    // The slot's has-best bit over two clocks: from the leaf's slot while its last triangle is
    // here, then at fin (a slot's bit cannot change in between: its previous leaf was merged
    // before it was unparked, and it is done only after its last leaf).
    let m1_has = b.delay("m1_slot_has", slot_bit_2(&b, "fin_has", best_valid, k, &[slot], fin_slot));
    let m1_empty = b.delay("m1_leaf_empty", acc_empty);
    let m1_tt = b.delay("m1_t_tri", b.cat(&[acc_t, acc_tri]));
    let m1_uv = b.delay("m1_u_v", acc_uv_now);
    // The leaf's best replaces the slot's when (¬leaf hit, 0, leaf t, tri) < (0, ¬slot hit,
    // slot t, tri): the chain compares (¬leaf hit, leaf t, tri) < (0, slot t, tri), and a
    // leaf hit into a slot without one is better whatever the chain says. Both parts are
    // registered apart (M2) and ORed there, and the best RAMs are written a clock later (M3):
    // the chain, the OR and the AND into the write enable in one clock were the default core's
    // slowest path at seed 1 (8.27 ns, 38 cells). The merge is reported from M2 as before; the
    // slot's best is read again only after its ray has been unparked, many clocks later.
    let (leaf_key, slot_key) = (b.cat(&[m1_empty, m1_tt]), b.cat(&[zero, st_tt]));
    // The write enable and the first hit, when made before M2's registers (a spread core): see
    // `best_we`.
    let (mut we_parts, mut first_hit_early) = (None, None);
    let (m2, m2_less) = if spread {
        // In a spread core the chain is cut in two halves registered apart (less above, or
        // equal above and less below): the whole chain after the slot's LUT-RAM read was among
        // the slowest paths of the four-unit core at a placement seed (7.37 ns).
        let (w, lo) = (leaf_key.width(), leaf_key.width() / 2);
        let (leaf_hi, slot_hi) = (leaf_key.slice(lo, w - lo), slot_key.slice(lo, w - lo));
        let (hi_less_c, hi_equal_c) =
            (lt_chain(leaf_hi, slot_hi).name("leaf_tt_hi_less"), leaf_hi.eq(slot_hi).name("leaf_tt_hi_equal"));
        let hi_less = b.delay("m2_tt_hi_less", hi_less_c);
        let hi_equal = b.delay("m2_tt_hi_equal", hi_equal_c);
        let lo_less =
            b.delay("m2_tt_lo_less", lt_chain(leaf_key.slice(0, lo), slot_key.slice(0, lo)).name("leaf_tt_lo_less"));
        let m1_first_hit = *first_hit_early.insert((!m1_has & !m1_empty).name("m1_first_hit"));
        let we_either = b.valid_delay("m2_we_either", (m1 & (m1_first_hit | hi_less_c)).name("m1_we_either"));
        let we_if_lo = b.valid_delay("m2_we_if_lo", (m1 & hi_equal_c).name("m1_we_if_lo"));
        we_parts = Some((we_either | (we_if_lo & lo_less)).name("m2_we"));
        (b.valid_delay("m2", m1), (hi_less | (hi_equal & lo_less)).name("m2_tt_less"))
    } else {
        let tt_less = lt_chain(leaf_key, slot_key).name("leaf_tt_less");
        let m2 = b.valid_delay("m2", m1);
        (m2, b.delay("m2_tt_less", tt_less))
    };
    let m1_first_hit = first_hit_early.unwrap_or_else(|| (!m1_has & !m1_empty).name("m1_first_hit"));
    let m2_first_hit = b.delay("m2_first_hit", m1_first_hit);
    let m2_better = (m2_less | m2_first_hit).name("leaf_better");
    let m2_hit = b.delay("m2_hit", (m1_has | !m1_empty).name("m1_hit"));
    let m2_slot = b.delay("m2_slot", m1_slot);
    let m2_sp = b.delay("m2_sp", m1_sp);
    let m2_tt = b.delay("m2_t_tri", m1_tt);
    let m2_uv = b.delay("m2_u_v", m1_uv);
    // Both cull limits (best t + 8) are made in M1 and the better picked in M2, so the OR is
    // followed by a select rather than an adder.
    let (tt_t, t_bits) = (tri.width(), t.width());
    let leaf_limit = m1_tt.slice(tt_t, t_bits).xsigned().resize(dist) + 8;
    let slot_limit = st_tt.slice(tt_t, t_bits).xsigned().resize(dist) + 8;
    let m2_leaf_limit = b.delay("m2_leaf_limit", leaf_limit.name("leaf_limit"));
    let m2_slot_limit = b.delay("m2_slot_limit", slot_limit.name("slot_limit"));
    // The write enable is one register of its own (not m3 ∧ better after them): it fans out
    // to every LUT-RAM cell of both best RAMs, spread over the die, and the AND's LUT placed
    // between them cost three placement seeds of the four-unit core 10.8–14.2 ns.
    // In a spread core the enable is one LUT after M2's registers: the leaf's hit into a slot
    // without one or the upper half's less (with m1) is registered apart from the upper half's
    // equal, so M2 has `either ∨ (if_lo ∧ lo_less)` left (the ORs and ANDs after the three
    // halves' registers into the enable's copies were 6.83 ns at a seed of the fitted core).
    let we = b.valid_delay("best_we", we_parts.unwrap_or_else(|| (m2 & m2_better).name("m2_we")));
    // The write address fans out to every LUT-RAM cell of both best RAMs: a register each.
    let m3_slot = b.delay("m3_slot", m2_slot);
    let m3_slots = b.copies(m3_slot, tt_mem.groups() + uv_mem.groups());
    let (tt_slots, uv_slots) = m3_slots.split_at(tt_mem.groups());
    // And so does the write enable: a copy per group (one register reaching all was among the
    // slowest paths at seeds 1 and 2, `best_we` → `best_u_v` cells, 6.68 ns, one LUT).
    let wes = b.copies(we, tt_mem.groups() + uv_mem.groups());
    let (tt_wes, uv_wes) = wes.split_at(tt_mem.groups());
    tt_mem.write(&b, tt_wes, tt_slots, b.delay("m3_t_tri", m2_tt));
    uv_mem.write(&b, uv_wes, uv_slots, b.delay("m3_u_v", m2_uv));
    let limit = m2_better.select(m2_leaf_limit, m2_slot_limit).name("merged_limit");
    // The merge reaches each traversal unit through registers of its own (valid, slot in the
    // unit, hit): one shared set drove both units' cull-limit LUT-RAM write enables through
    // the unit decode and an AND, across the die (12.1 ns at a seed of the external core).
    let sb = tag.slot_bits - lane_bits - unit_bits;
    let slot_r = b.delay("merge_slot_r", m2_slot.slice(0, sb));
    let hit_r = b.delay("merge_hit_r", m2_hit);
    // The register and its copies, one per unit.
    let per_unit = |r| -> Vec<S> { std::iter::once(r).chain(b.copies(r, units as usize - 1)).collect() };
    let (slots_u, hits_u) = (per_unit(slot_r), per_unit(hit_r));
    for u in 0..units {
        let mine = if unit_bits == 0 {
            m2
        } else {
            (m2 & m2_slot.slice(sb, unit_bits).eq(u as i128)).name(&format!("m2_unit{u}"))
        };
        b.output(&format!("merge_valid{u}"), b.valid_delay(&format!("merge_valid{u}_r"), mine));
        b.output(&format!("merge_slot{u}"), slots_u[u as usize]);
        b.output(&format!("merge_hit{u}"), hits_u[u as usize]);
    }
    b.output("merge_limit", b.delay("merge_limit_r", limit));
    b.output("merge_sp", b.delay("merge_sp_r", m2_sp));

    // A ray done: its best hit and id are read, then sent out; the slot is freed.
    // d0 holds the done slot here, by the RAMs and the slots' bits (the top's register that
    // feeds `done_slot` sits by its arbiter); the has-best bit is selected over d0 and d1.
    let d0 = b.valid_delay("d0", done_valid);
    let d0_slot = b.delay("d0_slot", done_slot);
    // A register per RAM it addresses (426 sinks a bit as one; DECISIONS 114).
    let d0_slots = b.copies(d0_slot, tt_mem.groups() + uv_mem.groups() + id_mem.groups());
    let (tt_slots, rest) = d0_slots.split_at(tt_mem.groups());
    let (uv_slots, id_slot) = rest.split_at(uv_mem.groups());
    let d_tt = tt_mem.read(&b, "done_t_tri", tt_slots);
    let d_uv = uv_mem.read(&b, "done_u_v", uv_slots);
    let d_id = id_mem.read(&b, "done_id", id_slot);
    let d1 = b.valid_delay("d1", d0);
    let d1_slot = b.delay("d1_slot", d0_slot);
    let d1_has = b.delay("d1_has", slot_bit_2(&b, "done_has", best_valid, k, &done_slots, d0_slot));
    let none = b.konst(Ty::u(k), 0);
    // The slots' one-hot words are decoded a stage early into registers: the set and the clear
    // then reach the k has-best bits through one LUT (with four units the set's decode after
    // `m2_better` was the slowest path of a placement seed: 90.7 MHz).
    let set = we.select(b.delay("m3_onehot", super::onehot(m2_slot, k)), none).name("best_set");
    let clear = d1.select(b.delay("d1_onehot", super::onehot(d0_slot, k)), none).name("best_clear");
    b.next(best_valid, (best_valid & !clear) | set);
    b.output("free_valid", b.valid_delay("free_valid_r", d1));
    b.output("free_slot", b.delay("free_slot_r", d1_slot));
    // The has-best bit masks four fields of 13–32 bits each: in a spread core a copy of its
    // register per field (one register reaching all 150 or so result bits was the slowest path
    // at a placement seed of the four-unit core, `d1_has` → `res_t`, 8.05 ns through one LUT).
    let has_copies = if spread { b.copies(d1_has, 4) } else { vec![d1_has; 4] };
    let res = |name: &str, x, mask: Option<S>| {
        let x = mask.map_or(x, |has| has.select(x, x.k(0)));
        b.output(&format!("res_{name}"), b.delay(&format!("res_{name}_r"), x.name(&format!("res_{name}_c"))));
    };
    let res_valid = b.reg("res_valid_r", Ty::BIT, Some(0));
    b.next(res_valid, d1);
    b.output("res_valid", res_valid);
    res("id", d_id, None);
    res("hit", d1_has, None);
    res("tri", d_tt.slice(0, tri.width()), Some(has_copies[0]));
    res("t", d_tt.slice(tri.width(), t.width()), Some(has_copies[1]));
    res("u", d_uv.slice(m_bits, m_bits), Some(has_copies[2]));
    res("v", d_uv.slice(0, m_bits), Some(has_copies[3]));
    b.finish()
}
