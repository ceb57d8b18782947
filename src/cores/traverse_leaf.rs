//! Where a traversal unit's leaves go (`traverse.rs` says what the unit does): the leaf
//! queue for the leaf stream, and in a spread core the leaf a parent's step sends itself
//! (DECISIONS 137): the pair ROM's fields of the near child, carried from N to G.

use super::fifo::{Fifo, fifo, narrow_fifo};
use super::traverse_stages::{LeafSend, Unit};
use crate::rtl::build::S;

impl<'b> Unit<'b> {
    /// The leaf queue for the leaf stream: (slot, first, count, tmin, sp) pushed with `push`.
    /// At a fast target the leaf is registered by its decode and again in the queue (its push
    /// register, by the queue's LUT RAM): the decode into the push register across the die
    /// was the slowest path at seed 3 (`n_valid_3` → `leaf_q_push`, 7.34 ns, 3.4 of it one
    /// route). A leaf then waits a clock more; nothing waits for it.
    pub(super) fn leaf_queue(&self, push: S<'b>, slot: S<'b>, fields: &[S<'b>], tmin: S<'b>, sp: S<'b>) -> Fifo<'b> {
        let (b, p) = (self.b, self.p);
        let parts: Vec<S<'b>> = [slot]
            .into_iter()
            .chain(fields.iter().copied())
            .chain([tmin.unsigned().resize(p.tmin_width()), sp])
            .collect();
        let leaf_in = b.cat(&parts);
        let (push_q, in_q) = if p.landing {
            (b.valid_delay("leaf_push_r", push), b.delay("leaf_in_r", leaf_in))
        } else {
            (push, leaf_in)
        };
        let pop = b.valid_delay("leaf_pop_r", self.inp.leaf_pop);
        // A spread core's queue in narrow groups: a pointer copy through its group's 16 cells
        // into the head's register was a slowest path of the fitted core at seed 1 (7.35 ns).
        if p.spread {
            narrow_fifo(b, "leaf_q", p.slots, push_q, in_q, pop)
        } else {
            fifo(b, "leaf_q", leaf_in.width(), p.slots, push_q, in_q, pop)
        }
    }

    /// N to F2 with `pair_rom_cycles` (`r`): the pair ROM is addressed a clock after N by the
    /// node's child pair and answers r clocks later; its near half (by the direction's sign,
    /// known a clock after N) or, for a node that is itself a leaf with entries, the node's
    /// own fields ride to F2 (a clock after F). `n` holds, as N sees them: the node's own leaf bit and fields,
    /// its `child`, and the sign a clock after N.
    pub(super) fn leaf_send(&self, r: u32, plane_latency: u32, n: [S<'b>; 4]) -> LeafSend<'b> {
        let (b, p) = (self.b, self.p);
        let [own_leaf, own_fields, child, negative_c] = n;
        let arrives = 1 + r;
        assert!(plane_latency > arrives, "the pair word arrives before F");
        let addr = b.delay("pair_addr_r", child.slice(1, (child.width() - 1).max(1)));
        b.output("pair_addr", addr);
        let word = self.inp.pair_word.expect("a pair word input");
        let fb = p.leaf_fields_bits();
        let negative = b.delay_line("pair_negative", negative_c, r);
        let near = negative.select(word.slice(fb, fb), word.slice(0, fb)).name("pair_near");
        let own = b.delay_line("own_leaf_p", own_leaf, arrives);
        let fields = own.select(b.delay_line("own_fields_p", own_fields, arrives), near);
        let near_leaf = near.slice(0, p.node_layout.field("count").width).ne(0);
        // To F2, a clock after F.
        let to_f2 = plane_latency - arrives + 1;
        LeafSend {
            own: b.delay_line("own_leaf_f2", own, to_f2),
            fields: b.delay_line("leaf_fields_f2", fields.name("leaf_fields_p"), to_f2),
            near_leaf: b.delay_line("near_leaf_f2", near_leaf.name("near_leaf_p"), to_f2),
        }
    }
}
