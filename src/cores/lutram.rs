//! A RAM in banks of 16 words, read over two clocks: the banks (one column of LUT-RAM cells
//! each on the ECP5) are read at the address and registered, then the bank is chosen. A wide
//! RAM of 64 or 128 words in LUTs spreads over tens of columns; read and registered in one
//! clock, its address register reached every cell and the word came back through a mux tree
//! (the slot core's critical paths: 4.1 ns of routing from the address register alone).

use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// Words per bank: a LUT-RAM cell's depth.
const BANK_WORDS: u32 = 16;

pub struct Banked {
    banks: Vec<usize>,
    width: u32,
}

/// A RAM of `words` words of `width` bits, all 0, in banks named NAME_b0, NAME_b1, ….
pub fn banked(b: &Builder, name: &str, width: u32, words: u32) -> Banked {
    let banks = (0..words.div_ceil(BANK_WORDS))
        .map(|k| b.ram(&format!("{name}_b{k}"), width, vec![0; BANK_WORDS.min(words) as usize]))
        .collect();
    Banked { banks, width }
}

fn low_bits(banks: usize, addr: S<'_>) -> u32 {
    if banks == 1 { addr.width() } else { BANK_WORDS.trailing_zeros() }
}

impl Banked {
    /// Writes `data` at `addr` when `we`.
    pub fn write<'b>(&self, b: &'b Builder, we: S<'b>, addr: S<'b>, data: S<'b>) {
        let lb = low_bits(self.banks.len(), addr);
        for (k, &mem) in self.banks.iter().enumerate() {
            let mine = if self.banks.len() == 1 { we } else { we & addr.slice(lb, addr.width() - lb).eq(k as i128) };
            b.ram_write(mem, mine, addr.slice(0, lb), data);
        }
    }

    /// The word at `early` (an address in this clock), in the next clock, when `late` must
    /// hold the same address (`early` a clock later). The word must not be written in
    /// between. Not registered: the caller registers it.
    pub fn read2<'b>(&self, b: &'b Builder, name: &str, early: S<'b>, late: S<'b>) -> S<'b> {
        let lb = low_bits(self.banks.len(), early);
        let words: Vec<S> =
            self.banks.iter().enumerate().map(|(k, &mem)| b.read(&format!("{name}_b{k}"), mem, early.slice(0, lb))).collect();
        if words.len() == 1 {
            return words[0];
        }
        let cases: Vec<(u128, S)> = words.iter().enumerate().map(|(k, &w)| (k as u128, w)).collect();
        b.case(late.slice(lb, late.width() - lb), &cases, b.konst(Ty::u(self.width), 0)).name(&format!("{name}_c"))
    }
}

/// Bit `slot` of the k-bit register `bits`, selected over two clocks: groups of 16 bits by the
/// slot's low bits from `early` into registers, then the group by the high bits of `late`
/// (`early` a clock later). A 128-to-1 select in one clock was the core's critical path, its
/// slot register placed across the die from the bits. The bit must not change in between.
pub fn select_bit2<'b>(b: &'b Builder, name: &str, bits: S<'b>, k: u32, early: S<'b>, late: S<'b>) -> S<'b> {
    let zero = b.konst(Ty::BIT, 0);
    let low = early.width().min(4);
    let groups: Vec<S> = (0..k.div_ceil(16))
        .map(|g| {
            let cases: Vec<(u128, S)> = (0..16.min(k - 16 * g)).map(|i| (i as u128, bits.bit(16 * g + i))).collect();
            b.delay(&format!("{name}_g{g}"), b.case(early.slice(0, low), &cases, zero).name(&format!("{name}_g{g}_c")))
        })
        .collect();
    if groups.len() == 1 {
        return groups[0];
    }
    let cases: Vec<(u128, S)> = groups.iter().enumerate().map(|(g, &x)| (g as u128, x)).collect();
    b.case(late.slice(4, late.width() - 4), &cases, zero).name(&format!("{name}_c"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;

    /// Random writes and two-clock reads of a 100-word RAM against a Vec.
    #[test]
    fn reads_what_was_written() {
        let b = Builder::new("t");
        let we = b.input("we", Ty::BIT);
        let wa = b.input("wa", Ty::u(7));
        let wd = b.input("wd", Ty::u(12));
        let ra = b.input("ra", Ty::u(7));
        let ram = banked(&b, "m", 12, 100);
        ram.write(&b, we, wa, wd);
        let late = b.delay("ra_d", ra);
        b.output("q", ram.read2(&b, "q", ra, late));
        let m = b.finish();
        let mut sim = Sim::new(&m);
        let h = |i: usize| m.handle(m.inputs[i]);
        let q = m.handle(m.outputs[0].1);
        let mut model = vec![0i128; 100];
        let mut x = 99u32;
        let mut want: Option<i128> = None;
        for _ in 0..5000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let (a, r, d) = ((x % 100) as i128, ((x >> 8) % 100) as i128, ((x >> 16) & 0xfff) as i128);
            let w = x & 0x10000000 != 0 && a != r;
            sim.set(h(0), w as i128);
            sim.set(h(1), a);
            sim.set(h(2), d);
            sim.set(h(3), r);
            sim.eval();
            if let Some(v) = want {
                assert_eq!(sim.get(q), v);
            }
            want = Some(model[r as usize]);
            if w {
                model[a as usize] = d;
            }
            sim.tick();
        }
    }
}
