//! The closest-hit unit: watches the intersection pipeline's output stream and keeps, for the
//! ray in flight, the smallest (t, triangle number) among accepted hits — a hit is accepted
//! only if t ≥ lower_t(leaf entry distance) (`golden::lower_t`). The traversal unit processes
//! rays one after another and the pipeline keeps their order, so one accumulator suffices:
//! when a ray's end token comes out, its result is emitted and the accumulator cleared.
//!
//! The pipeline tag: bits [0, tri_bits) the triangle number, then n + 2 bits of leaf entry
//! distance, then the end flag on top; an end token carries the ray id in the low bits.

use super::clock::ClockTarget;
use super::lt_chain;
use crate::rtl::build::Builder;
use crate::rtl::{Module, Ty};

#[derive(Clone, Copy, Debug)]
pub struct TagLayout {
    pub tri_bits: u32,
    pub tmin_bits: u32,
    pub id_bits: u32,
}

impl TagLayout {
    pub fn payload(&self) -> u32 {
        (self.tri_bits + self.tmin_bits).max(self.id_bits)
    }
    pub fn width(&self) -> u32 {
        self.payload() + 1
    }
}

/// Whether the closest-hit unit registers its input stream (and the acceptance test) before
/// comparing with the best hit: from this clock target up (`ClockTarget::splits`).
pub const STAGED_FROM_MHZ: u32 = 126;

/// Cycles from a pipeline result to the unit's accumulator: 2 when staged for the target.
pub fn input_latency(target: ClockTarget) -> u32 {
    2 * target.splits(STAGED_FROM_MHZ) as u32
}

/// Ports: valid, tag, hit, t (n + 1 bits), u, v (m bits) → res_valid, res_id, res_hit,
/// res_tri, res_t, res_u, res_v (t, u, v and tri read 0 for a miss), `input_latency` + 1
/// cycles after the end token.
pub fn closest_core(tag: TagLayout, n: u32, m_bits: u32, target: ClockTarget) -> Module {
    let staged = input_latency(target) > 0;
    let suffix = if staged { "_r2" } else { "" };
    let b = Builder::new(&format!("fxrt_closest_n{n}_m{m_bits}_tag{}{suffix}", tag.width()));
    let valid = b.input("valid", Ty::BIT);
    let tag_in = b.input("tag", Ty::u(tag.width()));
    let hit = b.input("hit", Ty::BIT);
    let t = b.input("t", Ty::u(n + 1));
    let u = b.input("u", Ty::u(m_bits));
    let v = b.input("v", Ty::u(m_bits));
    let end = tag_in.bit(tag.payload()).name("end");
    let tri = tag_in.slice(0, tag.tri_bits).name("tri");
    let tmin = tag_in.slice(tag.tri_bits, tag.tmin_bits).name("tmin");
    let id = tag_in.slice(0, tag.id_bits).name("id");

    // lower_t(tmin) = tmin − tmin/64 − 8, and t, both signed n + 3 bits. A hit is accepted
    // when t ≥ lower_t, i.e. when t + 8 ≥ tmin − tmin/64: two subtractions side by side, then
    // one comparison, rather than three carry chains in series.
    let dist = n + 3;
    let tmin_d = tmin.xsigned().resize(dist);
    let x = (tmin_d - (tmin_d >> 6)).name("tmin_less");
    let t8 = (t.xsigned().resize(dist) + 8).name("t_plus_8");
    // Staged: two register levels, (x, t + 8) and then the acceptance bit, so the
    // accumulator's compare starts from registers (a result arrives two cycles later;
    // nothing else changes). The bits that do not depend on the best hit (a valid hit, not an
    // end token, accepted) are ANDed into one `candidate` register on the way.
    let reg = |name: &str, x, k: u32| if staged { b.delay_line(&format!("in_{name}"), x, k) } else { x };
    let (x, t8) = (reg("tmin_less", x, 1), reg("t_plus_8", t8, 1));
    let (valid1, end1, hit1) = (reg("valid", valid, 1), reg("end", end, 1), reg("hit", hit, 1));
    let accepted = (!lt_chain(t8, x)).name("accepted");
    // Held inverted, the accumulator's compare taking it as its top bit (below); staged, its
    // register resets to 1 (no candidate), as the positive one started at 0.
    let no_candidate = (!(valid1 & !end1 & hit1 & accepted)).name("no_candidate_c");
    let no_candidate = if staged {
        let r = b.reg("in_no_candidate", Ty::BIT, Some(1));
        b.next(r, no_candidate);
        r
    } else {
        no_candidate
    };
    let finish = reg("finish", (valid1 & end1).name("finish_c"), 1);
    let (tri, id, t, u, v) = (reg("tri", tri, 2), reg("id", id, 2), reg("t", t, 2), reg("u", u, 2), reg("v", v, 2));

    // The best accepted hit of the ray in flight. Closer means (t, tri) < (best_t, best_tri)
    // in lexicographic order (equal t: the smaller triangle number wins), which is one
    // unsigned compare of the concatenations: one carry chain in the accumulator's loop
    // instead of a compare, an equality and a second compare side by side. The candidate bit
    // and whether there is a best hit yet go in as two more bits on top, so the chain's last
    // sum bit is `take` = candidate ∧ (no best hit ∨ closer) itself, the enable of the best-hit
    // registers, with no LUT between (`lt_chain`): (¬candidate, 0, t, tri) < (0, no best,
    // best_t, best_tri). `best_empty` is ¬best_valid in a register of its own.
    let best_valid = b.reg("best_valid", Ty::BIT, Some(0));
    let best_empty = b.reg("best_empty", Ty::BIT, Some(1));
    let best_t = b.reg("best_t", t.ty(), None);
    let best_tri = b.reg("best_tri", tri.ty(), None);
    let best_u = b.reg("best_u", u.ty(), None);
    let best_v = b.reg("best_v", v.ty(), None);
    let zero = b.konst(Ty::BIT, 0);
    let take = lt_chain(b.cat(&[no_candidate, zero, t, tri]), b.cat(&[zero, best_empty, best_t, best_tri])).name("take");
    for (r, x) in [(best_t, t), (best_tri, tri), (best_u, u), (best_v, v)] {
        b.next_when(r, take, x);
    }
    b.next(best_valid, finish.select(best_valid.k(0), take.select(best_valid.k(1), best_valid)));
    b.next(best_empty, finish.select(best_empty.k(1), take.select(best_empty.k(0), best_empty)));

    // The result registers, loaded by the end token; a miss reports zeros, so every output bit
    // is defined.
    let res_valid = b.reg("res_valid_r", Ty::BIT, Some(0));
    b.next(res_valid, finish);
    b.output("res_valid", res_valid);
    let res_hit = b.reg("res_hit_r", Ty::BIT, None);
    b.next_when(res_hit, finish, best_valid);
    b.output("res_hit", res_hit);
    for (name, x) in [("id", id), ("tri", best_tri), ("t", best_t), ("u", best_u), ("v", best_v)] {
        let masked = if name == "id" { x } else { best_valid.select(x, 0) };
        let r = b.reg(&format!("res_{name}_r"), x.ty(), None);
        b.next_when(r, finish, masked);
        b.output(&format!("res_{name}"), r);
    }
    b.finish()
}
