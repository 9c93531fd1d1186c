//! WGSL → SPIR-V with every floating-point operation marked `NoContraction`.
//!
//! WGSL lets a driver fuse a multiply and an add into one fma, and drivers go further: SPIR-V
//! arithmetic without the `NoContraction` decoration is, for Mesa's NIR, "inexact", free to be
//! fused and reassociated. On lavapipe `3y⁴ − 2y − d` comes out as fma(−2, y, 3y³·y − d), one
//! ulp away from the CPU's left-to-right value; in the JKR Newton solve next to the branch end
//! (a double root, where an ulp in the residual moves the root by √ulp) that ulp grows to
//! 7·10⁻⁹ relative. naga never writes `NoContraction`, so this module adds it to naga's SPIR-V:
//! the decoration forbids both fusing and reassociation, and the twins then agree to the bit.
//!
//! The result goes to the driver through wgpu's SPIR-V passthrough, which wgpu offers on Vulkan
//! only; elsewhere the shaders run as WGSL (see [`super::shader::FloatMode`]).

/// SPIR-V opcodes (SPIR-V 1.6 specification, section 3.52) of the floating-point arithmetic
/// instructions `NoContraction` applies to. Each has its result id in word 2.
const FLOAT_ARITHMETIC: &[u32] = &[
    127, // OpFNegate
    129, // OpFAdd
    131, // OpFSub
    133, // OpFMul
    136, // OpFDiv
    140, // OpFRem
    141, // OpFMod
    142, // OpVectorTimesScalar
    143, // OpMatrixTimesScalar
    144, // OpVectorTimesMatrix
    145, // OpMatrixTimesVector
    146, // OpMatrixTimesMatrix
    147, // OpOuterProduct
    148, // OpDot
];
const OP_DECORATE: u32 = 71;
const DECORATION_NO_CONTRACTION: u32 = 42;
/// OpTypeVoid ..= OpTypeForwardPointer: the first of these ends the annotation section.
const TYPE_DECLARATIONS: std::ops::RangeInclusive<u32> = 19..=39;
const HEADER_WORDS: usize = 5;

/// SPIR-V for a validated naga module, every float operation decorated `NoContraction`.
///
/// Bounds checks clamp indices into range (`Restrict`), as wgpu does on Vulkan without robust
/// buffer access: a stray index reads and writes inside the binding, never outside it.
///
/// With `entry`, only that compute entry point and the globals it uses are written (as wgpu
/// does for WGSL), and its bindings are renumbered 0, 1, 2, … in ascending order of their
/// WGSL numbers: wgpu's Vulkan backend numbers the bindings of a layout by their position in
/// it (and renumbers WGSL it compiles to match), so a passthrough module for a pipeline whose
/// layout holds exactly [`entry_bindings`] must do the same.
pub fn exact_spirv(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    entry: Option<&str>,
) -> Result<Vec<u32>, naga::back::spv::Error> {
    let mut options = options();
    let pipeline = entry.map(|name| {
        for (position, binding) in entry_bindings(module, info, name).into_iter().enumerate() {
            options.binding_map.insert(
                naga::ResourceBinding { group: 0, binding },
                naga::back::spv::BindingInfo {
                    descriptor_set: 0,
                    binding: position as u32,
                    binding_array_size: None,
                },
            );
        }
        naga::back::spv::PipelineOptions {
            shader_stage: naga::ShaderStage::Compute,
            entry_point: name.to_string(),
        }
    });
    let words = naga::back::spv::write_vec(module, info, &options, pipeline.as_ref())?;
    Ok(forbid_contraction(&words))
}

/// Binding numbers (group 0) the entry point `entry` uses, ascending; naga's analysis follows
/// calls, so a binding used by a helper counts.
pub fn entry_bindings(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    entry: &str,
) -> Vec<u32> {
    let index = module
        .entry_points
        .iter()
        .position(|e| e.name == entry)
        .unwrap_or_else(|| panic!("no entry point {entry}"));
    let uses = info.get_entry_point(index);
    let mut bindings: Vec<u32> = module
        .global_variables
        .iter()
        .filter(|(handle, _)| !uses[*handle].is_empty())
        .filter_map(|(_, var)| var.binding.as_ref().map(|b| b.binding))
        .collect();
    bindings.sort_unstable();
    bindings
}

fn options() -> naga::back::spv::Options<'static> {
    let mut options = naga::back::spv::Options::default();
    options.flags.remove(naga::back::spv::WriterFlags::DEBUG);
    options.bounds_check_policies = naga::proc::BoundsCheckPolicies {
        index: naga::proc::BoundsCheckPolicy::Restrict,
        buffer: naga::proc::BoundsCheckPolicy::Restrict,
        image_load: naga::proc::BoundsCheckPolicy::Restrict,
        binding_array: naga::proc::BoundsCheckPolicy::Unchecked,
    };
    options
}

/// `words` with an `OpDecorate %id NoContraction` for the result of every float arithmetic
/// instruction, placed where SPIR-V's logical layout wants annotations: before the first type
/// declaration. Everything else is copied unchanged.
pub fn forbid_contraction(words: &[u32]) -> Vec<u32> {
    let mut results = Vec::new();
    let mut first_type = None;
    let mut at = HEADER_WORDS;
    while at < words.len() {
        let opcode = words[at] & 0xffff;
        let count = (words[at] >> 16) as usize;
        assert!(
            count > 0 && at + count <= words.len(),
            "malformed SPIR-V at word {at}"
        );
        if FLOAT_ARITHMETIC.contains(&opcode) {
            results.push(words[at + 2]);
        }
        if first_type.is_none() && TYPE_DECLARATIONS.contains(&opcode) {
            first_type = Some(at);
        }
        at += count;
    }
    let split = first_type.unwrap_or(words.len());
    let mut out = Vec::with_capacity(words.len() + 3 * results.len());
    out.extend_from_slice(&words[..split]);
    for id in results {
        out.extend([(3 << 16) | OP_DECORATE, id, DECORATION_NO_CONTRACTION]);
    }
    out.extend_from_slice(&words[split..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (opcode, operands) of every instruction after the header.
    fn instructions(words: &[u32]) -> Vec<(u32, Vec<u32>)> {
        let mut out = Vec::new();
        let mut at = HEADER_WORDS;
        while at < words.len() {
            let count = (words[at] >> 16) as usize;
            out.push((words[at] & 0xffff, words[at + 1..at + count].to_vec()));
            at += count;
        }
        assert_eq!(at, words.len());
        out
    }

    /// naga's SPIR-V for `source`, and the same with the decorations added.
    fn spirv(source: &str) -> (Vec<u32>, Vec<u32>) {
        let module = naga::front::wgsl::parse_str(source).unwrap();
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            super::super::shader::CAPABILITIES,
        )
        .validate(&module)
        .unwrap();
        let plain = naga::back::spv::write_vec(&module, &info, &options(), None).unwrap();
        (plain, exact_spirv(&module, &info, None).unwrap())
    }

    fn is_no_contraction((op, operands): &(u32, Vec<u32>)) -> bool {
        *op == OP_DECORATE && operands[1] == DECORATION_NO_CONTRACTION
    }

    #[test]
    fn every_float_operation_is_decorated_and_nothing_else_changes() {
        let (plain, words) = spirv(
            "@group(0) @binding(0) var<storage, read_write> v: array<f64>;
             @compute @workgroup_size(1)
             fn main() {
                 let a = v[0]; let b = v[1]; let i = u32(v[2]);
                 v[3] = 3.0lf * a * b - 2.0lf * a - b / a;
                 v[4] = dot(vec3<f64>(a, b, a), vec3<f64>(b, a, b)) + f64(i + 1u) * -a;
             }",
        );
        let all = instructions(&words);
        let float_results: Vec<u32> = all
            .iter()
            .filter(|(op, _)| FLOAT_ARITHMETIC.contains(op))
            .map(|(_, operands)| operands[1])
            .collect();
        let decorated: Vec<u32> = all
            .iter()
            .filter(|i| is_no_contraction(i))
            .map(|(_, operands)| operands[0])
            .collect();
        assert!(float_results.len() >= 8, "{float_results:?}");
        assert_eq!(float_results, decorated);
        // Annotations precede all type declarations.
        let last_decoration = all.iter().rposition(is_no_contraction).unwrap();
        let first_type = all
            .iter()
            .position(|(op, _)| TYPE_DECLARATIONS.contains(op))
            .unwrap();
        assert!(last_decoration < first_type);
        // Without the added decorations, the words are naga's.
        assert_eq!(instructions(&plain), {
            let mut all = all;
            all.retain(|i| !is_no_contraction(i));
            all
        });
        assert_eq!(plain[..HEADER_WORDS], words[..HEADER_WORDS]);
    }

    #[test]
    fn integer_only_code_gets_no_decorations() {
        let (plain, words) = spirv(
            "@group(0) @binding(0) var<storage, read_write> v: array<u32>;
             @compute @workgroup_size(1)
             fn main() { v[0] = v[1] * 3u + v[2]; }",
        );
        assert_eq!(plain, words);
    }
}
