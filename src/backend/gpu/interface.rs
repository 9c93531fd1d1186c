//! The GPU engine's interface as the shaders declare it, generated at build time (`build.rs`):
//! [`Binding`] (every binding of shaders/engine/bindings.wgsl, by number) and
//! [`wgsl_constants`] (the shared numbers: work lists, flags, the diagnostics and row blocks);
//! [`Kernel`] (every entry point of shaders/passes/) lives in `backend::script`, which the CPU
//! engine runs too. The host names a buffer by its `Binding` variant and
//! a pass by its `Kernel` variant, so a typo is a compile error and a binding added to the WGSL
//! appears here (and must get a size in `buffers::Sizes::bytes`, an exhaustive match).
//!
//! The tests below hold the generated items to naga's reading of the same files.

include!(concat!(env!("OUT_DIR"), "/gpu_interface.rs"));
pub use crate::backend::script::Kernel;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::gpu::shader::{assemble_pass, engine_module, PASSES};

    #[test]
    fn bindings_are_the_wgsl_declarations_in_number_order() {
        let module = engine_module();
        let mut declared: Vec<(u32, String, naga::AddressSpace)> = module
            .global_variables
            .iter()
            .filter_map(|(_, v)| Some((v.binding.as_ref()?.binding, v.name.clone()?, v.space)))
            .collect();
        declared.sort_by_key(|d| d.0);
        assert_eq!(declared.len(), Binding::COUNT);
        for (binding, (number, name, space)) in Binding::ALL.iter().zip(&declared) {
            assert_eq!((*binding as u32, binding.name()), (*number, name.as_str()));
            let expected = match space {
                naga::AddressSpace::Uniform => "uniform",
                naga::AddressSpace::Storage { access }
                    if access.contains(naga::StorageAccess::STORE) =>
                {
                    "storage, read_write"
                }
                naga::AddressSpace::Storage { .. } => "storage, read",
                other => panic!("{name}: {other:?}"),
            };
            assert_eq!(binding.space(), expected, "{name}");
        }
    }

    #[test]
    fn the_constants_are_the_wgsl_u32_constants() {
        let module = engine_module();
        let mut from_naga: Vec<(String, usize)> = module
            .constants
            .iter()
            .filter_map(|(_, c)| match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => {
                    Some((c.name.clone()?, v as usize))
                }
                _ => None,
            })
            .collect();
        from_naga.sort();
        let mut generated: Vec<(String, usize)> = wgsl_constants::ALL
            .iter()
            .map(|(n, v)| (n.to_string(), *v))
            .collect();
        generated.sort();
        assert!(generated.len() > 50, "{} constants", generated.len());
        assert_eq!(generated, from_naga);
    }

    #[test]
    fn the_step_scripts_codes_are_the_wgsl_ones() {
        use crate::backend::script as s;
        for (name, rust) in [
            ("OWNER_EVENTS", s::OWNER_EVENTS),
            ("OWNER_CORRECTIONS", s::OWNER_CORRECTIONS),
            ("OWNER_WALLS", s::OWNER_WALLS),
            ("OWNER_INDEX", s::OWNER_INDEX),
            ("PAIR_TEST_BREAKS", s::PAIR_TEST_BREAKS),
            ("PAIR_TEST_BEYOND", s::PAIR_TEST_BEYOND),
        ] {
            let wgsl = wgsl_constants::ALL.iter().find(|(n, _)| *n == name);
            assert_eq!(wgsl.map(|(_, v)| *v), Some(rust as usize), "{name}");
        }
    }

    #[test]
    fn kernels_are_every_entry_point_of_the_passes() {
        let mut from_naga: Vec<(String, String)> = Vec::new();
        for pass in PASSES {
            let (module, _) = assemble_pass(pass.name()).unwrap().validate().unwrap();
            for ep in &module.entry_points {
                from_naga.push((pass.name().to_string(), ep.name.clone()));
            }
        }
        from_naga.sort();
        let mut generated: Vec<(String, String)> = Kernel::ALL
            .iter()
            .map(|k| (k.pass().to_string(), k.entry().to_string()))
            .collect();
        generated.sort();
        assert_eq!(generated, from_naga);
        for (i, k) in Kernel::ALL.iter().enumerate() {
            assert_eq!(*k as usize, i);
        }
    }
}
