// requires: double_f32
//
// shaders/engine/accumulators.wgsl in the mixed precision: each entry a double-f32.

struct TallyEntry {
    value: f32,
    value_lo: f32,
}

fn tally_entry(value: f32) -> TallyEntry {
    return TallyEntry(value, 0.0f);
}

fn accumulate(entry: TallyEntry, value: f32) -> TallyEntry {
    let sum = double_f32_add_f32(DoubleF32(entry.value, entry.value_lo), value);
    return TallyEntry(sum.hi, sum.lo);
}

fn tally_value(entry: TallyEntry) -> f32 {
    return entry.value + entry.value_lo;
}
