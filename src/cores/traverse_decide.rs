//! The traversal unit's last stages (`traverse.rs` says what the unit does): from N to F the
//! token rides along while the limits of `bih::inner_step`'s decision are made; in F the two
//! plane distances are compared by their roles; in G the decision pushes, enters or pops. A
//! unit that sends leaves (`pair_rom_cycles`) has F2 between F and G, where the leaf to send
//! is chosen from F's registered compare.

use super::fifo::Fifo;
use super::lt_chain;
use super::traverse_stages::{LeafSent, Queued, Returning, RingA, RingF, RingN, Token, Unit};
use crate::rtl::build::S;

impl<'b> Unit<'b> {
    /// N → F: the token rides along; the limits are made on the way (as `inner_step`'s
    /// compares, every one a strict less-than; when tmin > tmax no distance passes any limit).
    /// F: both distances arrive and are compared by their roles, registered for G. With
    /// `pair_rom_cycles`, F2: the registered compares and the token ride a clock more, and
    /// the leaf to send (and so whether the token returns) is decided from them.
    pub(super) fn ring_f(&self, nn: &RingN<'b>) -> RingF<'b> {
        let (b, n, l, nt, axis1, negative) = (self.b, self.p.n, nn.plane_latency, nn.token, nn.axis1, nn.negative);
        b.stage("ring_f", "N to F: the token rides along, the limits made on the way; F: the compares");
        let ring = match nn.leaves {
            Some(leaves) => nt.valid & !leaves,
            None => nt.valid,
        }
        .name("n_stays");
        // The token rides to F, and in a sending unit on to F2 (`f2`).
        let f2 = nn.send.is_some();
        let to_last = l + f2 as u32;
        let f_valid = b.valid_line("f_valid", ring, to_last);
        let f_inner = b.delay_line("f_inner", nn.is_inner, to_last);
        let f_slot = b.delay_line("f_slot", nt.slot, to_last);
        let f_tmin = b.delay_line("f_tmin", nt.tmin, to_last);
        let f_tmax = b.delay_line("f_tmax", nt.tmax, to_last);
        let f_sp = b.delay_line("f_sp", nt.sp, to_last);
        let f_child = b.delay_line("f_child", nn.child, to_last);
        let neg1 = b.delay("negative_n1", b.pick(axis1, nn.inv).msb());
        let (tmin1, tmax1) = (b.delay("tmin_n1", nt.tmin), b.delay("tmax_n1", nt.tmax));
        let tmax_p1 = b.delay("tmax_p1", (nt.tmax + 1).name("tmax_plus_1"));
        let tmin_m1 = b.delay("tmin_m1", (nt.tmin - 1).name("tmin_minus_1"));
        let tmin_le_tmax = b.delay("tmin_le_tmax", lt_chain(tmin1, tmax_p1).name("tmin_le_tmax_c"));
        let (tmin2, tmax2, tmax_p1_2, tmin_m1_2) = (
            b.delay("tmin_n2", tmin1),
            b.delay("tmax_n2", tmax1),
            b.delay("tmax_p1_n2", tmax_p1),
            b.delay("tmin_m1_n2", tmin_m1),
        );
        let never_below = tmax2.k(-(1i128 << (n + 2)));
        let never_above = tmax2.k((1i128 << (n + 2)) - 1);
        let limit_reg = |name: &str, if_negative: S<'b>, if_positive: S<'b>, never: S<'b>| {
            let x = tmin_le_tmax.select(neg1.select(if_negative, if_positive), never);
            b.delay_line(name, b.delay(&format!("{name}_n3"), x.name(&format!("{name}_c"))), l - 3)
        };
        let d0_hi = limit_reg("d0_hi", tmax_p1_2, tmax2, never_below);
        let d0_lo = limit_reg("d0_lo", tmin2, tmin_m1_2, never_above);
        let d1_hi = limit_reg("d1_hi", tmax2, tmax_p1_2, never_below);
        let d1_lo = limit_reg("d1_lo", tmin_m1_2, tmin2, never_above);

        // F: the compares, registered by role (for G; in a sending unit for F2, then G).
        // `to_g` is F's register of a value for G, and in a sending unit F2's after it.
        let to_g = |name: &str, x: S<'b>| {
            let r = b.delay(name, x);
            if f2 { b.delay(&format!("{name}_f2"), r) } else { r }
        };
        let [d0, d1] = nn.plane_t;
        let d0_below = lt_chain(d0, d0_hi).name("d0_below");
        let d0_above = lt_chain(d0_lo, d0).name("d0_above");
        let d1_below = lt_chain(d1, d1_hi).name("d1_below");
        let d1_above = lt_chain(d1_lo, d1).name("d1_above");
        let reg = |name: &str, if_negative: S<'b>, if_positive: S<'b>| {
            to_g(name, negative.select(if_negative, if_positive).name(&format!("{name}_c")))
        };
        let near_lt_tmax = reg("near_lt_tmax", d1_below, d0_below);
        let far_gt_tmin = reg("far_gt_tmin", d0_above, d1_above);
        let go_near_c = negative.select(d1_above, d0_above).name("go_near_c");
        let go_near_f = b.delay("go_near", go_near_c);
        let go_near = if f2 { b.delay("go_near_f2", go_near_f) } else { go_near_f };
        let go_far = reg("go_far", d0_below, d1_below);
        let near_end = to_g("near_end", negative.select(d1, d0));
        let far_start = to_g("far_start", negative.select(d0, d1));
        let g = Token {
            valid: b.valid_delay("g_valid", f_valid),
            slot: b.delay("g_slot", f_slot),
            node: b.delay("g_child", f_child),
            tmin: b.delay("g_tmin", f_tmin),
            tmax: b.delay("g_tmax", f_tmax),
            sp: b.delay("g_sp", f_sp),
        };
        // A leaf to queue in G: the node's own, or the near child entered (`enter_near` of G).
        // Decided in F2 from F's registered compare: with the compare's carry chain, the
        // decision and its route to the copies of `g_returns` by the entry stage were the
        // slowest paths of the fitted core at seed 1 (7.62 ns, 2.5 of it one route).
        let send = nn.send.map(|ls| {
            let send_c = (f_valid & (ls.own | (f_inner & go_near_f & ls.near_leaf))).name("leaf_send_c");
            LeafSent {
                send: b.valid_delay("g_leaf_send", send_c),
                own: b.delay("g_own_leaf", ls.own),
                fields: b.delay("g_leaf_fields", ls.fields),
                returns: b.valid_delay("g_returns", (f_valid & !send_c).name("returns_c")),
            }
        });
        let inner = b.delay("g_inner", f_inner);
        let negative = to_g("g_negative", negative);
        RingF { g, inner, negative, near_lt_tmax, far_gt_tmin, go_near, go_far, near_end, far_start, send }
    }

    /// G: the decision: push the far child (stack[slot][sp]) and enter the near one, enter one
    /// child, or pop. The token goes into R and is back at A in the next cycle.
    /// With `pair_rom_cycles`, G also queues a leaf (the token's own, or its near child
    /// entered), and the token does not go round: returns the leaf queue and the observation
    /// of a near child sent (valid, slot, node).
    pub(super) fn ring_g(
        &self,
        f: &RingF<'b>,
        r: &Returning<'b>,
        a: &RingA<'b>,
        q: &Queued<'b>,
    ) -> Option<(Fifo<'b>, [S<'b>; 3])> {
        let (b, g, node_bits, push) = (self.b, f.g, self.node_bits, &a.push);
        b.stage("ring_g", "G: the decision: push the far child and enter the near one, enter one, or pop");
        // Whether G's token goes round: every valid one, unless it queues a leaf.
        let returns = f.send.map_or(g.valid, |s| s.returns);
        // The entry stage's copy: E decides by it beside the queues, across the unit from G.
        b.drive(q.ring_g_valid, b.copies(returns, 1)[0]);
        let child_b = g.node + 1;
        let near = f.negative.select(child_b, g.node).resize(node_bits).name("near");
        let far = f.negative.select(g.node, child_b).resize(node_bits).name("far");
        let near_max = f.near_lt_tmax.select(f.near_end, g.tmax).name("near_max");
        let far_min = f.far_gt_tmin.select(f.far_start, g.tmin).name("far_min");
        let (enter_near, enter_far) =
            ((f.inner & f.go_near).name("enter_near"), (f.inner & !f.go_near & f.go_far).name("enter_far"));
        let push_now = (enter_near & f.go_far).name("push");
        let stack_bits = self.stack_bits;
        // The push is written a clock later, from registers (the far child's select and
        // increment into the block RAM's data pins was the slowest path at seed 3 of the
        // default core: `g_child`, 7.72 ns). Safe: the entry is read only by its slot's pop, a
        // ring pass later at the earliest (the token pushing enters its near child in A).
        b.drive(push[0], b.valid_delay("stack_we_r", push_now));
        b.drive(push[1], b.delay("stack_waddr_r", b.cat(&[g.slot, g.sp.resize(stack_bits)])));
        b.drive(push[2], b.delay("stack_wdata_r", b.cat(&[far, far_min.unsigned(), g.tmax.unsigned()])));
        let rt = r.token;
        b.next(rt.valid, returns);
        let pop = (!(enter_near | enter_far)).name("g_pop");
        b.next(r.pop, pop);
        b.next(rt.slot, g.slot);
        b.next(rt.node, enter_near.select(near, far));
        b.next(rt.tmin, enter_far.select(far_min, g.tmin));
        b.next(rt.tmax, enter_near.select(near_max, g.tmax));
        let sp_next = push_now.select(g.sp + 1, g.sp);
        b.next(rt.sp, sp_next);
        let sp_zero = g.sp.eq(0).name("g_sp_zero");
        b.next(r.sp_zero, !push_now & sp_zero);
        let sp_m1 = push_now.select(g.sp, g.sp - 1).name("g_sp_m1");
        b.next(r.sp_m1, sp_m1);
        b.next(r.done, (pop & sp_zero).name("g_done"));
        // The stack read address of the token in A next clock: the returning one's, else the
        // queued one's (E takes one exactly when G's token does not return).
        let returning = b.cat(&[g.slot, sp_m1.resize(stack_bits)]);
        b.next(a.raddr, returns.select(returning, q.raddr_next).name("stack_raddr_next"));
        f.send.map(|s| {
            let leafq = self.leaf_queue(s.send, g.slot, &[s.fields], g.tmin, sp_next);
            (leafq, [(s.send & !s.own).name("sent_c"), g.slot, near])
        })
    }
}
