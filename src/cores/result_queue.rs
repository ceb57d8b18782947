//! The core's result port: a first-word-fall-through queue with credits between the
//! closest-hit unit and an output register driving `res_*` (DECISIONS 75, docs/CORE.md).

use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// Results a consumer has not taken yet, at most: the result queue's depth. Chosen so that a
/// consumer always ready never holds a ray back (a result holds its place for 7 clocks, from
/// leaving its done queue to leaving the result queue, and at most one leaves per clock).
pub const RESULT_QUEUE: u32 = 16;

/// The result ports behind a queue with credits and an output register: a result is taken on
/// a clock with `res_valid` and `res_ready` both 1 and is held until then. A finished ray
/// leaves its done queue only while the result queue has a place it has not promised
/// (`credit_ok`): when the consumer stops, rays finish into the done queues, their slots stay
/// taken, and `ray_ready` falls when the units are full — nothing is lost and nothing waits on
/// a combinational path from `res_ready`. `field(name)` is the closest-hit units'
/// `res_{name}`; `popped` is their `done_valid` (a ray leaving its queue, a clock after the
/// pop).
pub fn result_queue<'b>(
    b: &'b Builder,
    field: &dyn Fn(&str) -> S<'b>,
    popped: S<'b>,
    res_ready: S<'b>,
    credit_ok: S<'b>,
) {
    let bit = Ty::BIT;
    // Each field taken once (with several pipelines `field` builds the lanes' select).
    let fields: std::collections::BTreeMap<&str, S> =
        ["id", "hit", "tri", "t", "u", "v"].into_iter().map(|name| (name, field(name))).collect();
    let words = [b.cat(&[fields["id"], fields["hit"], fields["tri"], fields["t"]]), b.cat(&[fields["u"], fields["v"]])];
    let take = b.wire("res_take", bit);
    // Two read ports: the take picks between the words after the RAM reads, not before them
    // (through the read pointer into the RAM it was a slowest path at seed 3, 7.01 ns, 48
    // endpoints); the second port costs 33 LUT-RAM cells.
    let (heads, nonempty) = super::fifo::fifo_words(b, "res_q", RESULT_QUEUE, field("valid"), &words, take, true);
    // The ports are registers (`res_out_*`), loaded from the queue's head whenever they are
    // empty or taken: the head's select through the consumer's logic was a slowest path at
    // seeds 2 and 3 (7.26 ns into the place-and-route wrapper's first XOR). The queue is taken
    // when the output takes its head.
    let out_valid = b.reg("res_out_valid", bit, Some(0));
    let room = (!out_valid | res_ready).name("res_out_room");
    b.drive(take, (nonempty & room).name("res_take_c"));
    b.next(out_valid, (nonempty | !room).name("res_out_valid_c"));
    let heads: Vec<S> = heads
        .iter()
        .enumerate()
        .map(|(k, &head)| {
            let r = b.reg(&format!("res_out{k}"), head.ty(), None);
            b.next_when(r, take, head);
            r
        })
        .collect();
    // Places not promised, counted with the pops a clock late (`popped`): the queue then holds
    // at most RESULT_QUEUE − credits + popped results, so a pop needs credits − popped ≥ 1,
    // which credits ≥ 2 a clock earlier (registered: `credit_ok`) guarantees.
    let w = RESULT_QUEUE.next_power_of_two().trailing_zeros() + 2;
    let credits = b.reg("res_credits", Ty::u(w), Some(RESULT_QUEUE as i128));
    // The next count either way, each one adder from registers, picked by the take (from
    // `res_ready`, a clock's last arrival): through the adder it was a slowest path at seed 1
    // (7.09 ns).
    let if_taken = (credits + (!popped).resize(w)).name("res_credits_if_take");
    let if_not = (credits - popped.resize(w)).name("res_credits_if_not");
    b.next(credits, take.select(if_taken, if_not).name("res_credits_next"));
    b.next(credit_ok, at_least_two_next(credits, popped, take));
    b.output("res_valid", out_valid);
    // Each word's fields, least significant first (`cat` takes the most significant first).
    let mut out = std::collections::BTreeMap::new();
    for (word, names) in [(0, ["t", "tri", "hit", "id"].as_slice()), (1, ["v", "u"].as_slice())] {
        let mut lsb = 0;
        for name in names {
            let width = fields[name].width();
            out.insert(*name, heads[word].slice(lsb, width).name(&format!("res_{name}_q")));
            lsb += width;
        }
    }
    for name in ["id", "hit", "tri", "t", "u", "v"] {
        b.output(&format!("res_{name}"), out[name]);
    }
}

/// Whether `credits − popped + take` (the credits' next value) is 2 or more, from compares of
/// the register with the two bits picking one: the take is a clock's last arrival (from
/// `res_ready`), and through the adder and its compare it was the slowest path of a placement
/// of the external core (10.9 ns).
fn at_least_two_next<'b>(credits: S<'b>, popped: S<'b>, take: S<'b>) -> S<'b> {
    let [ge1, ge2, ge3] = [1, 2, 3].map(|k: i128| credits.ge(k).name(&format!("res_credits_ge{k}")));
    let ok_if_taken = popped.select(ge2, ge1);
    let ok_if_not = popped.select(ge3, ge2);
    take.select(ok_if_taken, ok_if_not).name("res_credit_ok_c")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;

    /// The compares give the credits' next value ≥ 2 for every credit count, pop and take.
    #[test]
    fn credit_ok_is_the_next_count_at_least_two() {
        let b = Builder::new("t");
        let (credits, popped, take) =
            (b.input("credits", Ty::u(6)), b.input("popped", Ty::BIT), b.input("take", Ty::BIT));
        b.output("ok", at_least_two_next(credits, popped, take));
        let m = b.finish();
        let mut sim = Sim::new(&m);
        let h: Vec<_> = (0..3).map(|k| m.handle(m.inputs[k])).collect();
        let ok = m.handle(m.outputs[0].1);
        for c in 0..=(RESULT_QUEUE as i128 + 1) {
            for (p, t) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                if c - p < 0 {
                    continue; // a pop is counted against a credit promised
                }
                for (k, v) in [c, p, t].into_iter().enumerate() {
                    sim.set(h[k], v);
                }
                sim.eval();
                assert_eq!(sim.get(ok), i128::from(c - p + t >= 2), "credits {c}, popped {p}, take {t}");
            }
        }
    }
}
