//! Bit counts shared by every layer: address and value widths, and the depth memories are
//! built with. No ray tracing here: the RTL layer and the scene's ROM images both use it.

/// Bits needed to address `count` entries (at least 1).
pub fn addr_bits(count: usize) -> u32 {
    (usize::BITS - count.saturating_sub(1).leading_zeros()).max(1)
}

/// The depth a memory of `words` words is built with: the next power of two (at least 2, as
/// the address has at least one bit), padded with zero words, so every address of the port is
/// a real word (the simulators read 0 beyond the end too). A block-RAM policy, here
/// at the bottom so the scene's cost estimates and the RTL layer share it.
pub fn rom_depth(words: usize) -> usize {
    words.next_power_of_two().max(2)
}

/// Bits needed to address a memory of `words` words as built (`rom_depth`).
pub fn rom_addr_bits(words: usize) -> u32 {
    rom_depth(words).trailing_zeros().max(1)
}

/// Bits needed to hold the unsigned value `v` (at least 1).
pub fn value_bits(v: usize) -> u32 {
    (usize::BITS - v.leading_zeros()).max(1)
}
