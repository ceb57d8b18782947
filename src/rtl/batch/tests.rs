//! The batched simulator against the cycle simulator, cycle by cycle.

use super::*;
use crate::rng::SplitMix64;
use crate::rtl::sim::Sim;
use crate::rtl::{BinOp, Module, Sig, UnOp};

/// A random three-stage feed-forward module over narrow and wide signals, with every
/// combinational definition kind and registers chained to various depths.
fn random_pipeline(seed: u64) -> Module {
    let mut r = SplitMix64(seed);
    let mut m = Module::new("batch_check");
    let mut pool: Vec<Sig> = [
        Ty::s(13),
        Ty::s(13),
        Ty::u(9),
        Ty::u(9),
        Ty::s(40),
        Ty::s(40),
        Ty::u(63),
        Ty::s(64),
        Ty::u(64),
        Ty::s(90),
        Ty::s(90),
    ]
    .iter()
    .enumerate()
    .map(|(i, t)| m.input(&format!("in{i}"), *t))
    .collect();
    let k = m.konst("k", Ty::u(9), 300);
    pool.push(k);
    for stage in 0..3 {
        let mut next = Vec::new();
        for j in 0..24 {
            let a = pool[r.next_u64() as usize % pool.len()];
            let same: Vec<Sig> = pool.iter().copied().filter(|x| x.ty == a.ty && x.id != a.id).collect();
            let b = if same.is_empty() { a } else { same[r.next_u64() as usize % same.len()] };
            let name = format!("op{stage}_{j}");
            let s = match r.next_u64() % 14 {
                0 => m.add(&name, a, b),
                1 => m.sub(&name, a, b),
                2 => m.bin(&name, BinOp::Xor, a, b),
                3 if a.ty.width * 2 <= 128 => m.mul(&name, a, b),
                4 => m.bin(&name, BinOp::Lt, a, b),
                5 => m.bin(&name, BinOp::Le, a, b),
                6 => m.un(&name, UnOp::Neg, a),
                7 => m.un(&name, UnOp::Not, a),
                8 if a.ty.width > 1 => m.shr(&name, a, 1 + (r.next_u64() % (a.ty.width as u64 - 1)) as u32),
                9 => m.shl(&name, a, (r.next_u64() % a.ty.width as u64) as u32),
                10 => m.resize(&name, a, 1 + (r.next_u64() % 100) as u32),
                11 => {
                    let sel = m.bit(&format!("{name}_sel"), a, 0);
                    m.mux(&name, sel, b, a)
                }
                12 if a.ty.width >= 3 => {
                    let sel = m.slice(&format!("{name}_sel"), a, 1, 2);
                    m.case(&name, sel, &[(0, a), (2, b)], b)
                }
                _ if a.ty.width + 9 <= 128 => m.concat(&name, &[a, k]),
                _ => m.un(&name, UnOp::AsUnsigned, a),
            };
            let depth = 1 + r.next_u64() % 3;
            let mut d = s;
            for i in 0..depth {
                d = m.delay(&format!("{name}_d{i}"), d);
            }
            next.push(d);
            if r.next_u64().is_multiple_of(3) {
                m.output(&format!("o{stage}_{j}"), d);
            }
        }
        pool.extend(next);
    }
    m
}

#[test]
fn batches_match_the_cycle_simulator() {
    for seed in 0..12 {
        let m = random_pipeline(seed);
        let mut sim = Sim::new(&m);
        let mut batch = BatchSim::new(&m, 37).expect("feed-forward");
        let ins: Vec<Sig> = m.inputs.iter().map(|&i| m.handle(i)).collect();
        let outs: Vec<Sig> = m.outputs.iter().map(|(_, i)| m.handle(*i)).collect();
        let mut r = SplitMix64(seed + 100);
        let cycles = 300;
        let stim: Vec<Vec<i128>> = (0..cycles)
            .map(|_| {
                ins.iter()
                    .map(|s| s.ty.value(s.ty.wrap(((r.next_u64() as i128) << 64) | r.next_u64() as i128)))
                    .collect()
            })
            .collect();
        let mut want = Vec::new();
        for st in &stim {
            for (s, v) in ins.iter().zip(st) {
                sim.set(*s, *v);
            }
            sim.tick();
            want.push(outs.iter().map(|o| sim.get(*o)).collect::<Vec<_>>());
        }
        let mut got = vec![vec![0i128; outs.len()]; cycles];
        batch.run(cycles, |c, k| stim[c][k], |c, k, v| got[c][k] = v);
        for c in 0..cycles {
            assert_eq!(got[c], want[c], "seed {seed}, cycle {c}");
        }
    }
}

#[test]
fn signed_sub() {
    let mut m = Module::new("s");
    let a = m.input("a", Ty::s(13));
    let b = m.input("b", Ty::s(13));
    let d = m.sub("d", a, b);
    let q = m.delay("q", d);
    m.output("q", q);
    let mut batch = BatchSim::new(&m, 4).unwrap();
    let mut got = vec![0; 6];
    batch.run(6, |c, k| if k == 0 { c as i128 } else { 3 }, |c, _, v| got[c] = v);
    assert_eq!(got, vec![-3, -2, -1, 0, 1, 2]);
}

/// The random pipeline plus feedback: an accumulator with enable, a counter with reset
/// value, a RAM written and read back, a ROM, and a comb output of registers.
fn with_state(seed: u64) -> Module {
    let mut m = random_pipeline(seed);
    let a = m.handle(m.inputs[2]); // u(9)
    let b = m.handle(m.inputs[3]); // u(9)
    let en = m.bit("acc_en", a, 3);
    let acc = m.reg("acc", Ty::u(9), Some(7));
    // A ROM inside the loop: the accumulator adds the word its own low bits address.
    let loop_rom = m.rom("steps", 9, (0..16u128).map(|i| (i * 113 + 5) % 512).collect());
    let acc_low = m.slice("acc_low", acc, 0, 4);
    let step = m.rom_read("acc_step", loop_rom, acc_low);
    let sum_a = m.add("acc_sum_a", acc, b);
    let sum = m.add("acc_sum", sum_a, step);
    m.connect(acc, sum, Some(en));
    let cnt = m.reg("count", Ty::u(5), Some(3));
    let one = m.konst("one5", Ty::u(5), 1);
    let inc = m.add("count_inc", cnt, one);
    m.connect(cnt, inc, None);
    let ram = m.ram("mem", 9, (0..32u128).map(|i| i * 3).collect());
    let we = m.bit("mem_we", b, 0);
    m.ram_write(ram, we, cnt, acc);
    let raddr = m.slice("mem_raddr", a, 0, 5);
    let q = m.rom_read("mem_q", ram, raddr);
    // Feedback through the RAM: the accumulator's next value depends on what it wrote.
    let rom = m.rom("table", 7, (0..32u128).map(|i| (i * 37) % 128).collect());
    let t = m.rom_read("table_q", rom, cnt);
    let mixed = m.bin("mixed", BinOp::Xor, q, acc);
    let st = m.delay("mixed_d", mixed);
    let both = m.concat("both", &[st, t]);
    m.output("o_acc", acc);
    m.output("o_count", cnt);
    m.output("o_mem", q);
    m.output("o_both", both);
    m
}

#[test]
fn state_machines_memories_and_feedback_match_the_cycle_simulator() {
    for seed in 0..8 {
        let m = with_state(seed);
        let mut sim = Sim::new(&m);
        let mut batch = BatchSim::new(&m, 23).expect("no combinational input-to-output path");
        let ins: Vec<Sig> = m.inputs.iter().map(|&i| m.handle(i)).collect();
        let outs: Vec<Sig> = m.outputs.iter().map(|(_, i)| m.handle(*i)).collect();
        let mut r = SplitMix64(seed + 7);
        let cycles = 200;
        let stim: Vec<Vec<i128>> = (0..cycles)
            .map(|_| {
                ins.iter()
                    .map(|s| s.ty.value(s.ty.wrap(((r.next_u64() as i128) << 64) | r.next_u64() as i128)))
                    .collect()
            })
            .collect();
        let mut want = Vec::new();
        for st in &stim {
            for (s, v) in ins.iter().zip(st) {
                sim.set(*s, *v);
            }
            sim.tick();
            want.push(outs.iter().map(|o| sim.get(*o)).collect::<Vec<_>>());
        }
        let mut got = vec![vec![0i128; outs.len()]; cycles];
        batch.run(cycles, |c, k| stim[c][k], |c, k, v| got[c][k] = v);
        for c in 0..cycles {
            assert_eq!(got[c], want[c], "seed {seed}, cycle {c}");
        }
    }
}

#[test]
fn a_combinational_input_to_output_path_is_declined() {
    let mut m = Module::new("comb");
    let a = m.input("a", Ty::u(8));
    let b = m.not("b", a);
    m.output("b", b);
    assert!(BatchSim::new(&m, 8).is_none());
}
