//! The traversal unit's parts (`traverse.rs` says what the unit does and wires them): the ring
//! token, and each stage of the ring the token goes round, built by a
//! method of `Unit`, in the order the stages are printed.

use super::brom::bram;
use super::fifo::Fifo;
use super::free_list::{FreeList, free_list};
use super::plane::{PlaneIssue, plane_unit};
use super::traverse_params::{TraverseParams, field};
use super::wide_ram::{WideRam, group_widths};
use super::{lt_chain, onehot, slot_bit_2, slot_bit_groups};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};
use crate::scene::rom::rom_addr_bits;

/// A token's fields in the ring.
#[derive(Clone, Copy)]
pub(super) struct Token<'b> {
    pub(super) valid: S<'b>,
    pub(super) slot: S<'b>,
    pub(super) node: S<'b>,
    pub(super) tmin: S<'b>,
    pub(super) tmax: S<'b>,
    pub(super) sp: S<'b>,
}

impl<'b> Token<'b> {
    /// The token `depth` clocks later, in the stage's registers `{stage}_valid`,
    /// `{stage}_slot`, … (the valid bit cleared by `rst`); each field passes through
    /// `through(field, value)` on the way in, in field order.
    pub(super) fn delayed(
        self,
        b: &'b Builder,
        stage: &str,
        depth: u32,
        through: impl Fn(&str, S<'b>) -> S<'b>,
    ) -> Token<'b> {
        let line = |field: &str, x: S<'b>| b.delay_line(&format!("{stage}_{field}"), through(field, x), depth);
        Token {
            valid: b.valid_line(&format!("{stage}_valid"), through("valid", self.valid), depth),
            slot: line("slot", self.slot),
            node: line("node", self.node),
            tmin: line("tmin", self.tmin),
            tmax: line("tmax", self.tmax),
            sp: line("sp", self.sp),
        }
    }
}

/// The retry queue: its head (when `ready`: its fill is in) and its ports.
#[derive(Clone, Copy)]
pub(super) struct RetryQueue<'b> {
    pub(super) ready: S<'b>,
    /// Driven by the queues' arbiter: the head goes into the ring.
    pub(super) pop: S<'b>,
    pub(super) slot: S<'b>,
    pub(super) node: S<'b>,
    pub(super) tmin: S<'b>,
    pub(super) tmax: S<'b>,
    pub(super) sp: S<'b>,
    /// Driven in N (`retry_push`): a node step that missed, and its entry.
    pub(super) push: S<'b>,
    pub(super) entry: S<'b>,
}

/// The unit's input ports.
pub(super) struct Inputs<'b> {
    pub(super) new_valid: S<'b>,
    pub(super) new_slot: S<'b>,
    pub(super) new_tmax: S<'b>,
    pub(super) new_miss: S<'b>,
    pub(super) merge_valid: S<'b>,
    pub(super) merge_slot: S<'b>,
    pub(super) merge_hit: S<'b>,
    pub(super) merge_limit: S<'b>,
    pub(super) merge_sp: S<'b>,
    pub(super) free_valid: S<'b>,
    pub(super) free_slot: S<'b>,
    pub(super) alloc: S<'b>,
    pub(super) leaf_pop: S<'b>,
    pub(super) done_pop: S<'b>,
    pub(super) node_word: S<'b>,
    /// With `pair_rom_cycles`: the pair ROM's word at `pair_addr`, that many clocks after it.
    pub(super) pair_word: Option<S<'b>>,
    /// With a node cache: its answer in N besides the word (hit; when a miss, the fill to wait
    /// for) and its `done` counter.
    pub(super) cache: Option<NodeAnswer<'b>>,
}

/// The node cache's answer and fill counter (`cache::Answer`, `cache::Cache::done`).
#[derive(Clone, Copy)]
pub(super) struct NodeAnswer<'b> {
    pub(super) hit: S<'b>,
    pub(super) wait: S<'b>,
    pub(super) done: S<'b>,
}

/// What every stage of the unit reads: the builder, the widths, the inputs and the ray RAMs.
pub(super) struct Unit<'b> {
    pub(super) b: &'b Builder,
    pub(super) p: &'b TraverseParams,
    pub(super) inp: Inputs<'b>,
    /// The ray RAMs (origin; reciprocal direction per axis): written when the top accepts a
    /// ray, read in N for the plane units.
    pub(super) o_mem: WideRam,
    pub(super) inv_mem: [WideRam; 3],
    pub(super) sb: u32,
    pub(super) spw: u32,
    pub(super) node_bits: u32,
    /// Address bits of a slot's stack and of the leaf table.
    pub(super) stack_bits: u32,
    pub(super) leaf_bits: u32,
    pub(super) dist: Ty,
}

/// The token entering A: R's or a queued ray's, and the stack read it starts.
pub(super) struct RingA<'b> {
    pub(super) valid: S<'b>,
    pub(super) slot: S<'b>,
    pub(super) sp: S<'b>,
    pub(super) sp_m1: S<'b>,
    pub(super) done: S<'b>,
    pub(super) from_stack: S<'b>,
    /// The stack word (two clocks after A), its read address register (loaded in G) and its
    /// write port (driven in G).
    pub(super) stack_top: S<'b>,
    pub(super) raddr: S<'b>,
    pub(super) push: [S<'b>; 3],
}

/// The queues' head, registered for A.
pub(super) struct Queued<'b> {
    pub(super) ring_g_valid: S<'b>,
    pub(super) valid: S<'b>,
    pub(super) new: S<'b>,
    pub(super) slot: S<'b>,
    pub(super) sp: S<'b>,
    pub(super) sp_zero: S<'b>,
    pub(super) sp_m1: S<'b>,
    pub(super) tmax: S<'b>,
    /// The token taken will be done in A (a new ray that misses the box, an unparked ray with
    /// an empty stack): a register.
    pub(super) done: S<'b>,
    /// The taken token's stack read address, before A's register (`RingA::raddr`).
    pub(super) raddr_next: S<'b>,
    /// With a node cache: the queued token is a node step that missed, back from the retry
    /// queue with its node and tmin (tmax and sp come in `tmax`, `sp`).
    pub(super) retry: Option<Retried<'b>>,
}

/// A node step back from the retry queue (registered for A), and the queue's push port
/// (driven in N: `Unit::retry_push`).
#[derive(Clone, Copy)]
pub(super) struct Retried<'b> {
    pub(super) valid: S<'b>,
    pub(super) node: S<'b>,
    pub(super) tmin: S<'b>,
    pub(super) push: S<'b>,
    pub(super) entry: S<'b>,
}

/// R: the token back from G, with its pop flag and sp = 0, sp − 1 made in G.
pub(super) struct Returning<'b> {
    pub(super) token: Token<'b>,
    pub(super) pop: S<'b>,
    pub(super) sp_zero: S<'b>,
    pub(super) sp_m1: S<'b>,
    /// A pop of an empty stack: the token is done in A.
    pub(super) done: S<'b>,
}

/// N: the token with its node word.
pub(super) struct RingN<'b> {
    pub(super) token: Token<'b>,
    pub(super) culled: S<'b>,
    pub(super) visit: S<'b>,
    pub(super) is_inner: S<'b>,
    /// The token leaves the ring: a leaf queued, or (with a node cache) a miss. None when no
    /// token leaves in N (leaves are queued in G: `send`).
    pub(super) leaves: Option<S<'b>>,
    /// The leaf queue, when leaves are queued in N.
    pub(super) leafq: Option<Fifo<'b>>,
    /// With `pair_rom_cycles`: the leaf G may send, as F2 sees it.
    pub(super) send: Option<LeafSend<'b>>,
    /// The node's axis a clock after N, and whether the ray's direction is negative on it
    /// (as seen in F).
    pub(super) axis1: S<'b>,
    pub(super) negative: S<'b>,
    pub(super) child: S<'b>,
    pub(super) inv: [S<'b>; 3],
    pub(super) plane_t: [S<'b>; 2],
    pub(super) plane_latency: u32,
}

/// With `pair_rom_cycles`, in F2: whether the token's own node is a leaf with entries (popped,
/// or the root), the leaf fields (first above count) G would queue — the node's own, else its
/// near child's from the pair ROM — and whether the near child is a leaf with entries.
#[derive(Clone, Copy)]
pub(super) struct LeafSend<'b> {
    pub(super) own: S<'b>,
    pub(super) fields: S<'b>,
    pub(super) near_leaf: S<'b>,
}

/// With `pair_rom_cycles`, in G (registers loaded in F2): a leaf is queued (`send`: the
/// token's own node, else its near child entered), the token's own node is that leaf
/// (`own`), its fields, and whether the token goes round again (`returns`: valid, nothing
/// queued).
#[derive(Clone, Copy)]
pub(super) struct LeafSent<'b> {
    pub(super) send: S<'b>,
    pub(super) own: S<'b>,
    pub(super) fields: S<'b>,
    pub(super) returns: S<'b>,
}

/// G's operands: the token, and F's compares by role.
pub(super) struct RingF<'b> {
    pub(super) g: Token<'b>,
    pub(super) inner: S<'b>,
    pub(super) negative: S<'b>,
    pub(super) near_lt_tmax: S<'b>,
    pub(super) far_gt_tmin: S<'b>,
    pub(super) go_near: S<'b>,
    pub(super) go_far: S<'b>,
    pub(super) near_end: S<'b>,
    pub(super) far_start: S<'b>,
    /// With `pair_rom_cycles`: G's leaf to queue.
    pub(super) send: Option<LeafSent<'b>>,
}

impl<'b> Unit<'b> {
    /// The input ports, and the ray RAMs' write port.
    pub(super) fn new(b: &'b Builder, p: &'b TraverseParams) -> Unit<'b> {
        let (k, n, dist, sb, spw, bit) = (p.slots, p.n, p.dist_ty(), p.slot_bits(), p.sp_width(), Ty::BIT);
        let slot_ty = Ty::u(sb);
        // The ray RAMs' writes: a write enable and a slot per group of LUT-RAM columns, each
        // from a register of the top's own (`ray_port`): one `accept` through a unit select to
        // every cell was a slowest path at seed 2 (7.19 ns).
        let groups = p.ray_ram_widths().map(|w| group_widths(w).len());
        let (ray_we, ray_slot): (Vec<S>, Vec<S>) = (0..p.ray_ram_groups())
            .map(|g| (b.input(&format!("ray_we_g{g}"), bit), b.input(&format!("ray_slot_g{g}"), slot_ty)))
            .unzip();
        let o_in = ["ox", "oy", "oz"].map(|s| b.input(s, Ty::u(n)));
        let inv_in = ["invx", "invy", "invz"].map(|s| b.input(s, Ty::s(p.inv_width())));
        let mut inp = Inputs {
            new_valid: b.input("new_valid", bit),
            new_slot: b.input("new_slot", slot_ty),
            new_tmax: b.input("new_tmax", dist),
            new_miss: b.input("new_miss", bit),
            merge_valid: b.input("merge_valid", bit),
            merge_slot: b.input("merge_slot", slot_ty),
            merge_hit: b.input("merge_hit", bit),
            merge_limit: b.input("merge_limit", dist),
            merge_sp: b.input("merge_sp", Ty::u(spw)),
            free_valid: b.input("free_valid", bit),
            free_slot: b.input("free_slot", slot_ty),
            alloc: b.input("alloc", bit),
            leaf_pop: b.input("leaf_pop", bit),
            done_pop: b.input("done_pop", bit),
            // The node ROM is the core's (two units share one through a block RAM's two
            // ports): the unit sends the address in C and gets the word `node_rom_cycles`
            // later, in N.
            node_word: b.input("node_word", Ty::u(p.node_layout.width)),
            pair_word: p.pair_rom_cycles.map(|_| b.input("pair_word", Ty::u(2 * p.leaf_fields_bits()))),
            cache: p.node_cache.then(|| NodeAnswer {
                hit: b.input("node_hit", bit),
                wait: b.input("node_wait", Ty::u(super::cache::SEQ_BITS)),
                done: b.input("node_done", Ty::u(super::cache::SEQ_BITS)),
            }),
        };
        if p.spread {
            // A spread unit registers the merge where it arrives: the closest-hit unit's
            // `merge_valid` register, across the die, into the k has-best bits' LUTs was a
            // slowest path of the fitted core at a seed (6.77 ns, 10 endpoint groups). Every
            // use of a merge (the has-best set, the cull limit's write, the unpark) is a clock
            // later alike, so a slot is unparked with its limit and bit as before.
            inp.merge_valid = b.valid_delay("merge_valid_in", inp.merge_valid);
            inp.merge_slot = b.delay("merge_slot_in", inp.merge_slot);
            inp.merge_hit = b.delay("merge_hit_in", inp.merge_hit);
            inp.merge_limit = b.delay("merge_limit_in", inp.merge_limit);
            inp.merge_sp = b.delay("merge_sp_in", inp.merge_sp);
        }
        let [o_mem, ix_mem, iy_mem, iz_mem] = ["ray_o", "ray_invx", "ray_invy", "ray_invz"]
            .map(|name| WideRam::new(b, name, if name == "ray_o" { 3 * n } else { p.inv_width() }, k as usize));
        let data =
            [b.cat(&[o_in[2], o_in[1], o_in[0]]), inv_in[0].unsigned(), inv_in[1].unsigned(), inv_in[2].unsigned()];
        let [wes, slots] = [&ray_we, &ray_slot].map(|v| super::wide_ram::runs(v, &groups));
        for (r, ram) in [&o_mem, &ix_mem, &iy_mem, &iz_mem].into_iter().enumerate() {
            ram.write(b, &wes[r], &slots[r], data[r]);
        }
        let inv_mem = [ix_mem, iy_mem, iz_mem];
        let (node_bits, leaf_bits) = (p.node_bits, p.leaf_bits);
        let stack_bits = rom_addr_bits(p.stack_depth as usize);
        Unit { b, p, inp, o_mem, inv_mem, sb, spw, node_bits, stack_bits, leaf_bits, dist }
    }

    pub(super) fn slots(&self) -> FreeList<'b> {
        let (b, inp) = (self.b, &self.inp);
        b.stage("slots", "the free list: the next free slot for the top, the slots holding a ray");
        free_list(b, self.p.slots, self.sb, inp.alloc, inp.free_valid, inp.free_slot)
    }

    pub(super) fn returning(&self) -> Returning<'b> {
        let (b, spw, dist) = (self.b, self.spw, self.dist);
        b.stage("ring_r", "R: the token back from G, loaded in G");
        let valid = b.reg("r_valid", Ty::BIT, Some(0));
        let pop = b.reg("r_pop", Ty::BIT, None);
        let sp_zero = b.reg("r_sp_zero", Ty::BIT, None);
        let sp_m1 = b.reg("r_sp_m1", Ty::u(spw), None);
        let done = b.reg("r_done", Ty::BIT, None);
        let token = Token {
            valid,
            slot: b.reg("r_slot", Ty::u(self.sb), None),
            node: b.reg("r_node", Ty::u(self.node_bits), None),
            tmin: b.reg("r_tmin", dist, None),
            tmax: b.reg("r_tmax", dist, None),
            sp: b.reg("r_sp", Ty::u(spw), None),
        };
        Returning { token, pop, sp_zero, sp_m1, done }
    }

    /// A: the returning token, else a queued ray; a pop of an empty stack or a ray that misses
    /// the scene box is done; a pop reads the slot's stack at sp − 1.
    pub(super) fn ring_a(&self, r: &Returning<'b>, q: &Queued<'b>) -> RingA<'b> {
        let (b, k, sb, dist) = (self.b, self.p.slots, self.sb, self.dist);
        b.stage("ring_a", "A: the returning token or a queued ray; a pop reads the stack; done rays leave");
        let rv = r.token.valid;
        let valid = (rv | q.valid).name("a_valid");
        let slot = rv.select(r.token.slot, q.slot).name("a_slot");
        let not_popped = match q.retry {
            Some(t) => !(q.new | t.valid),
            None => !q.new,
        };
        let pop = rv.select(r.pop, not_popped).name("a_pop");
        let sp = rv.select(r.token.sp, q.new.select(q.sp.k(0), q.sp)).name("a_sp");
        let sp_zero = rv.select(r.sp_zero, q.new | q.sp_zero).name("a_sp_zero");
        let sp_m1 = rv.select(r.sp_m1, q.sp_m1).name("a_sp_m1");
        // Done: a pop of an empty stack or a new ray that misses the box (both decided a clock
        // before, in G and E).
        let done = ((rv & r.done) | (!rv & q.valid & q.done)).name("a_done");
        let from_stack = (pop & !sp_zero).name("a_from_stack");
        let stack_bits = self.stack_bits;
        // The stack: a block RAM read in two clocks (`brom::bram`), written in G.
        let stack_w = self.node_bits + 2 * dist.width;
        let push = [
            b.wire("stack_we", Ty::BIT),
            b.wire("stack_waddr", Ty::u(sb + stack_bits)),
            b.wire("stack_wdata", Ty::u(stack_w)),
        ];
        // The read address (slot, sp − 1) of A's token, loaded a clock before by G or E
        // (`ring_g`): selected in A, the returning token's valid bit fanned out to the address
        // pins was a slowest path of a traversal unit at seed 2 (7.57 ns).
        let raddr = b.reg("stack_raddr", Ty::u(sb + stack_bits), None);
        // One stack of 2^stack_bits words per slot number the address can hold: a slot number has
        // at least one bit, so one slot still takes two stacks' worth of address space.
        let words = (k.max(2) as usize) << stack_bits;
        let stack_top =
            bram(b, "u_stack", &format!("stack_w{stack_w}"), stack_w, words, push[0], push[1], push[2], raddr);
        RingA { valid, slot, sp, sp_m1, done, from_stack, stack_top, raddr, push }
    }

    /// A queued token's field: the retried step's (`field`) or `otherwise` (a new or unparked
    /// ray's).
    fn queued(&self, q: &Queued<'b>, field: impl Fn(&Retried<'b>) -> S<'b>, otherwise: S<'b>) -> S<'b> {
        match &q.retry {
            Some(t) => t.valid.select(field(t), otherwise),
            None => otherwise,
        }
    }

    /// B, B2: the token waits two clocks for the stack word (the block's output register).
    pub(super) fn ring_b(&self, a: &RingA<'b>, r: &Returning<'b>, q: &Queued<'b>) -> (Token<'b>, S<'b>) {
        let (b, rt) = (self.b, r.token);
        b.stage("ring_b", "B, B2: the token waits two clocks for the stack word");
        let bt = Token {
            valid: b.valid_delay("b_valid", (a.valid & !a.done).name("a_live")),
            slot: b.delay("b_slot", a.slot),
            node: b
                .delay("b_node", rt.valid.select(rt.node, self.queued(q, |t| t.node, rt.node.k(self.p.root as i128)))),
            tmin: b.delay("b_tmin", rt.valid.select(rt.tmin, self.queued(q, |t| t.tmin, rt.tmin.k(0)))),
            tmax: b.delay("b_tmax", rt.valid.select(rt.tmax, q.tmax)),
            sp: b.delay("b_sp", a.from_stack.select(a.sp_m1, a.sp)),
        };
        let from_stack = b.delay_line("b_from_stack", a.from_stack, 2);
        (bt.delayed(b, "b2", 1, |_, x| x), from_stack)
    }

    /// C: a popped entry (far node, far_min, tmax) from the stack word; the node ROM is
    /// addressed; the cull test: lower_t(tmin) > best t ⟺ tmin − tmin/64 > best t + 8
    /// (`golden::lower_t`), only when the slot has a best hit. Returns C's token, the cull
    /// decision registered (two clocks after C) and as seen in N, and with a node cache the
    /// lookup (valid, node) a clock after C.
    pub(super) fn ring_c(
        &self,
        bt: Token<'b>,
        from_stack: S<'b>,
        top: S<'b>,
        q: &Queued<'b>,
    ) -> (Token<'b>, [S<'b>; 2], Option<[S<'b>; 2]>) {
        let (b, k, dist, inp) = (self.b, self.p.slots, self.dist, &self.inp);
        b.stage("ring_c", "C: a popped entry from the stack word; the node ROM addressed; the cull test");
        let top_tmax = top.slice(0, dist.width).signed();
        let top_tmin = top.slice(dist.width, dist.width).signed();
        let top_node = top.slice(2 * dist.width, self.node_bits);
        let b_slot = bt.slot;
        let c = bt.delayed(b, "c", 1, |field, x| match field {
            "node" => from_stack.select(top_node, x),
            "tmin" => from_stack.select(top_tmin, x),
            "tmax" => from_stack.select(top_tmax, x),
            _ => x,
        });
        // In a spread core the limit's LUT RAM is read in groups of columns, each at a copy of
        // the slot of its own (`wide_ram`): one copy into all its cells was a slowest path of
        // the fitted core at seed 1 (`c_slot_c1` → `limit_q`, 7.06 ns).
        let limit_mem = if self.p.spread {
            WideRam::new(b, "cull_limit", dist.width, k as usize)
        } else {
            WideRam::whole(b, "cull_limit", dist.width, k as usize)
        };
        let limit_we = (inp.merge_valid & inp.merge_hit).name("limit_we");
        limit_mem.write(b, &[limit_we], &[inp.merge_slot], inp.merge_limit.unsigned());
        // The slot addresses the limit's LUT RAM and selects the has-best bit: a register each
        // (the select behind the shared one was 10.2 ns at a seed of the external core).
        let c_slots = b.copies(c.slot, limit_mem.groups() + 1);
        let limit = limit_mem.read(b, "limit_q", &c_slots[..limit_mem.groups()]).signed();
        let c_slot_has = c_slots[limit_mem.groups()];
        let has_best = b.reg("has_best", Ty::u(k), Some(0));
        let x = b.delay("cull_x", (c.tmin - (c.tmin >> 6)).name("tmin_less"));
        let has_best_kept = b.wire("has_best_kept", Ty::u(k));
        // The slot's bit over two clocks (`slot_bit_2`): groups of 16 by B's slot, then the group
        // by C's slot; the 64-to-1 select from C's slot register in one clock was a slowest path
        // at seeds 2 and 3 (7.72, 7.39 ns). The bit as it is in C is the bits after B's clear
        // (`has_best_kept`, registers of the unit's own) or a merge's set in B's clock for the
        // slot: compared with B's slot and registered beside the groups (the set's decode from
        // the merge ports, across the die, before the groups was 8.07 ns at a seed).
        // B's slot in a copy per group (and one for the merge compare): one copy reaching the
        // four groups' selects was 6.66 ns at seed 3.
        let early = b.copies(b_slot, 1 + slot_bit_groups(k) as usize);
        let set_in_b = (inp.merge_valid & inp.merge_hit & inp.merge_slot.eq(early[0])).name("b_slot_merged_c");
        let set_in_b = b.delay("b_slot_merged", set_in_b);
        let grouped = slot_bit_2(b, "slot_has_best", has_best_kept, k, &early[1..], c_slot_has);
        let hb = b.delay("cull_has_best", (grouped | set_in_b).name("slot_has_best_now"));
        // A spread unit without a node cache registers the compare and the has-best bit apart
        // and ANDs them after (the same value in the same clock): the bit's register, placed
        // by the slots' groups that load it, into the AND after the compare's chain was
        // 6.86 ns at a seed of the fitted core. The AND then only feeds `culled_n`.
        let split = self.p.spread && !self.p.node_cache && self.p.node_rom_cycles > 2;
        let culled_c = (!split).then(|| (hb & lt_chain(limit, x)).name("culled_c"));
        // With a node cache, the lookup a clock after C; the cull test, known then, withdraws
        // it a clock later (`culled`, the cache's `Lookup::cancel`): a culled entry fetches
        // nothing.
        let lookup = self.p.node_cache.then(|| [b.valid_delay("look_valid", c.valid), b.delay("look_node", c.node)]);
        let culled_first = match culled_c {
            Some(culled_c) => b.delay("culled", culled_c),
            None => {
                let less = b.delay("culled_less", lt_chain(limit, x).name("limit_less_x"));
                (b.delay("culled_has_best", hb) & less).name("culled")
            }
        };
        let culled = b.delay_line("culled_n", culled_first, self.p.node_rom_cycles - 2);
        let onehot_or_0 = |v: S<'b>, slot: S<'b>| v.select(onehot(slot, k), b.konst(Ty::u(k), 0));
        let set_best = onehot_or_0(inp.merge_valid & inp.merge_hit, inp.merge_slot).name("best_set");
        // A new ray's bit is cleared a clock after A, from a register (the decode of A's slot
        // behind A's selects, into the k bits, was 7.5 ns at seed 1 of the default core): it
        // is read first at C, two clocks after A, and no merge for a slot comes while its
        // new ray is in A (the slot's previous ray was done after its last merge). A new ray
        // in A is always the queued token (E takes one only when no token returns), so the
        // decode is of the queue's registers, not of A's select by `r_valid` (8.59 ns into
        // `best_clear` at seed 2).
        // In groups of 16 bits, each decoded from copies of `q_new` and `q_slot` of its own: one
        // `q_new` reaching all k decodes was the slowest path at seeds 1 and 2 (7.91 ns, a route).
        let groups = k.div_ceil(16);
        let (news, slots) = (b.copies(q.new, groups as usize), b.copies(q.slot, groups as usize));
        let clear_groups: Vec<S<'b>> = (0..groups)
            .rev()
            .map(|g| {
                let (new, slot) = (news[g as usize], slots[g as usize]);
                let bits = 16.min(k - 16 * g);
                let dec: Vec<S<'b>> = (16 * g..16 * g + bits).rev().map(|i| new & slot.eq(i as i128)).collect();
                b.cat(&dec)
            })
            .collect();
        let clear_best = b.delay("best_clear", b.cat(&clear_groups).name("best_clear_c"));
        b.drive(has_best_kept, (has_best & !clear_best).name("has_best_kept_c"));
        b.next(has_best, has_best_kept | set_best);
        (c, [culled_first, culled], lookup)
    }

    /// N: the node word. A culled entry or an empty leaf goes on as a pop; a leaf with entries
    /// is queued for the leaf stream and leaves the ring; an inner node issues both plane
    /// distances, one to each of two plane units, with the slot's ray from the ray RAMs.
    pub(super) fn ring_n(&self, c: Token<'b>, culled: S<'b>, q: &Queued<'b>) -> RingN<'b> {
        let (b, p, n, word) = (self.b, self.p, self.p.n, self.inp.node_word);
        b.stage("ring_n", "N: the node word; a leaf queued, an inner node to the plane units");
        let token = c.delayed(b, "n", p.node_rom_cycles, |_, x| x);
        let node_l = &p.node_layout;
        let nf = |name: &str| field(&format!("nw_{name}"), word, node_l.field(name), 0);
        let (w_axis, w_clip0, w_clip1, w_child, w_first, w_count) =
            (nf("axis"), nf("clip0"), nf("clip1"), nf("child"), nf("first"), nf("count"));
        let w_leaf = w_axis.eq(3).name("nw_is_leaf");
        // With a node cache only a hit is a visit; a miss leaves the ring for the retry queue.
        let visit = match (self.inp.cache, q.retry) {
            (Some(cache), Some(_)) => token.valid & !culled & cache.hit,
            _ => token.valid & !culled,
        }
        .name("visit_c");
        let is_inner = (visit & !w_leaf).name("is_inner");
        let own_leaf = (visit & w_leaf & w_count.ne(0)).name("leaf_push");
        let own_fields = [w_first.resize(self.leaf_bits), w_count];
        // Leaves are queued here, unless G queues them (`pair_rom_cycles`).
        let (leaves, leafq) = if p.pair_rom_cycles.is_some() {
            (None, None)
        } else {
            let leaves = match (self.inp.cache, q.retry) {
                (Some(cache), Some(r)) => own_leaf | self.retry_push(token, culled, cache, r.push, r.entry),
                _ => own_leaf,
            };
            let t = token;
            (Some(leaves), Some(self.leaf_queue(own_leaf, t.slot, &own_fields, t.tmin, t.sp)))
        };
        // The plane units, one per clip plane, fed the slot's ray from the ray RAMs (read in N, in
        // the units' second stage in N + 1). The read address in a register per RAM: one
        // register reaching all four RAMs' LUT-RAM slices and bank selects had 694 sinks a bit
        // (K = 64, teapot-fine).
        let early = b.delay_line("n_ray_slot_early", c.slot, p.node_rom_cycles - 1);
        let addr = b.delay("n_ray_slot", early);
        // A register per group of the RAMs' columns (`wide_ram`): one per RAM was a slowest
        // path into the origins' groups at seed 2 (7.08 ns).
        let addrs = super::wide_ram::address_registers(b, addr, p.ray_ram_groups());
        let counts = p.ray_ram_widths().map(|w| group_widths(w).len());
        let reads = super::wide_ram::runs(&addrs, &counts);
        let o_word = self.o_mem.read(b, "ray_o_q", &reads[0]);
        let o = [0, 1, 2].map(|a| o_word.slice(a * n, n));
        let inv = [0, 1, 2]
            .map(|a| self.inv_mem[a].read(b, &format!("ray_inv{}_q", ["x", "y", "z"][a]), &reads[a + 1]).signed());
        let issue =
            |last: i128, plane: S<'b>| PlaneIssue { valid: is_inner, last: is_inner.k(last), plane, axis: w_axis };
        let pu0 = plane_unit(b, n, p.c, o, inv, issue(0, w_clip0), p.product);
        let pu1 = plane_unit(b, n, p.c, o, inv, issue(1, w_clip1), p.product);
        // At a fast target each distance lands in a register by the compares (the plane
        // unit's own sits by the DSP column): `plane_t` → `go_near` was the slowest path at
        // seed 1 (7.03 ns, 3.2 of it the route from the product to the compare chain).
        let land = |pu: &super::plane::PlaneResult<'b>, name: &str| {
            if p.landing { b.delay(name, pu.t) } else { pu.t }
        };
        let plane_t = [land(&pu0, "plane_t_land0"), land(&pu1, "plane_t_land1")];
        let plane_latency = pu0.latency + p.landing as u32;
        assert!(plane_latency >= 4, "the decision limits need 3 cycles after N");
        // The axis's direction sign, for the roles of the two distances in F and G.
        let axis1 = b.delay("axis_n1", w_axis);
        let negative_c = b.pick(axis1, inv).msb().name("negative_c");
        let negative = b.delay_line("negative", negative_c, plane_latency - 1);
        let send = p
            .pair_rom_cycles
            .map(|r| self.leaf_send(r, plane_latency, [own_leaf, b.cat(&own_fields), w_child, negative_c]));
        RingN {
            token,
            culled,
            visit,
            is_inner,
            leaves,
            leafq,
            send,
            axis1,
            negative,
            child: w_child,
            inv,
            plane_t,
            plane_latency,
        }
    }
}
