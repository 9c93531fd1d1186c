// The per-monomer energy tally's entries, which add one step's small terms to a running sum.
// In the exact precision (this file) an entry is an f64. The mixed precision assembles
// shaders/mixed_engine/accumulators.wgsl in its place: a double-f32 in the same 8 bytes, since
// an f32 sum of 1000 steps' terms keeps only 10⁻⁴ of them (DESIGN.md, "Precision").

struct TallyEntry {
    value: f64,
}

fn tally_entry(value: f64) -> TallyEntry {
    return TallyEntry(value);
}

fn accumulate(entry: TallyEntry, value: f64) -> TallyEntry {
    return TallyEntry(entry.value + value);
}

fn tally_value(entry: TallyEntry) -> f64 {
    return entry.value;
}
