//! The closest-hit unit: watches the intersection pipeline's output stream and keeps, for the
//! ray in flight, the smallest (t, triangle number) among accepted hits — a hit is accepted
//! only if t ≥ lower_t(leaf entry distance) (`golden::lower_t`). The traversal unit processes
//! rays one after another and the pipeline keeps their order, so one accumulator suffices:
//! when a ray's end token comes out, its result is emitted and the accumulator cleared.
//!
//! The pipeline tag: bits [0, tri_bits) the triangle number, then n + 2 bits of leaf entry
//! distance, then the end flag on top; an end token carries the ray id in the low bits.

use super::intersect::as_signed_wider;
use crate::rtl::{Module, Sig, Ty};

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

/// Ports: valid, tag, hit, t (n + 1 bits), u, v (m bits) → res_valid, res_id, res_hit,
/// res_tri, res_t, res_u, res_v (t, u, v and tri read 0 for a miss).
pub fn closest_core(tag: TagLayout, n: u32, m_bits: u32) -> Module {
    let mut m = Module::new(&format!("fxrt_closest_n{n}_m{m_bits}_tag{}", tag.width()));
    let valid = m.input("valid", Ty::BIT);
    let tag_in = m.input("tag", Ty::u(tag.width()));
    let hit = m.input("hit", Ty::BIT);
    let t = m.input("t", Ty::u(n + 1));
    let u = m.input("u", Ty::u(m_bits));
    let v = m.input("v", Ty::u(m_bits));
    let end = m.bit("end", tag_in, tag.payload());
    let tri = m.slice("tri", tag_in, 0, tag.tri_bits);
    let tmin = m.slice("tmin", tag_in, tag.tri_bits, tag.tmin_bits);
    let id = m.slice("id", tag_in, 0, tag.id_bits);

    // lower_t(tmin) = tmin − tmin/64 − 8, and t, both signed n + 3 bits.
    let dist = Ty::s(n + 3);
    let tmin_s = as_signed_wider(&mut m, "tmin_s", tmin);
    let tmin_s = m.resize("tmin_d", tmin_s, dist.width);
    let sixty4th = m.shr("tmin_64th", tmin_s, 6);
    let eight = m.konst("eight", dist, 8);
    let lower_a = m.sub("lower_a", tmin_s, sixty4th);
    let lower = m.sub("lower_t", lower_a, eight);
    let t_s = as_signed_wider(&mut m, "t_s", t);
    let t_d = m.resize("t_d", t_s, dist.width);
    let too_near = m.lt("too_near", t_d, lower);
    let accepted = m.not("accepted", too_near);

    let best_valid = m.reg("best_valid", Ty::BIT, Some(0));
    let best_t = m.reg("best_t", t.ty, None);
    let best_tri = m.reg("best_tri", tri.ty, None);
    let best_u = m.reg("best_u", u.ty, None);
    let best_v = m.reg("best_v", v.ty, None);
    let t_less = m.lt("t_less", t, best_t);
    let t_same = m.equals("t_same", t, best_t);
    let tri_less = m.lt("tri_less", tri, best_tri);
    let tie_won = m.and("tie_won", t_same, tri_less);
    let closer = m.or("closer", t_less, tie_won);
    let first = m.not("first", best_valid);
    let better = m.or("better", first, closer);
    let not_end = m.not("not_end", end);
    let candidate = m.and("candidate", valid, not_end);
    let a = m.and("take_a", candidate, hit);
    let b = m.and("take_b", a, accepted);
    let take = m.and("take", b, better);
    let finish = m.and("finish", valid, end);
    for (r, x) in [(best_t, t), (best_tri, tri), (best_u, u), (best_v, v)] {
        m.connect(r, x, Some(take));
    }
    let one = m.konst("one", Ty::BIT, 1);
    let zero = m.konst("zero", Ty::BIT, 0);
    let bv_a = m.mux("best_valid_a", take, one, best_valid);
    let bv_next = m.mux("best_valid_next", finish, zero, bv_a);
    m.connect(best_valid, bv_next, None);

    // The result register, loaded by the end token.
    let res_valid = m.reg("res_valid_r", Ty::BIT, Some(0));
    m.connect(res_valid, finish, None);
    let outs: [(&str, Sig); 5] = [("id", id), ("tri", best_tri), ("t", best_t), ("u", best_u), ("v", best_v)];
    m.output("res_valid", res_valid);
    let res_hit = m.reg("res_hit_r", Ty::BIT, None);
    m.connect(res_hit, best_valid, Some(finish));
    m.output("res_hit", res_hit);
    for (name, x) in outs {
        // A miss reports zeros, so every output bit is defined.
        let masked = if name == "id" {
            x
        } else {
            let z = m.konst(&format!("{name}_zero"), x.ty, 0);
            m.mux(&format!("{name}_masked"), best_valid, x, z)
        };
        let r = m.reg(&format!("res_{name}_r"), x.ty, None);
        m.connect(r, masked, Some(finish));
        m.output(&format!("res_{name}"), r);
    }
    m
}
