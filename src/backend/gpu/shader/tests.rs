//! The registry matches the files, every file validates, and errors point at the file a
//! person edits.

use super::*;
use std::collections::BTreeSet;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn wgsl_files(dir: &str) -> BTreeSet<String> {
    std::fs::read_dir(root().join(dir))
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            name.ends_with(".wgsl").then(|| format!("{dir}/{name}"))
        })
        .collect()
}

fn all_files() -> impl Iterator<Item = &'static Source> {
    PASSES
        .iter()
        .chain(PROBES)
        .chain(MODEL)
        .chain(ENGINE)
        .chain(MIXED)
}

#[test]
fn every_shader_file_is_registered() {
    let paths =
        |list: &[Source]| -> BTreeSet<String> { list.iter().map(|s| s.path.to_string()).collect() };
    assert_eq!(paths(MODEL), wgsl_files("shaders/model"));
    assert_eq!(paths(ENGINE), wgsl_files("shaders/engine"));
    assert_eq!(paths(MIXED), wgsl_files("shaders/mixed"));
    assert_eq!(paths(MIXED_ENGINE), wgsl_files("shaders/mixed_engine"));
    assert_eq!(paths(PASSES), wgsl_files("shaders/passes"));
    assert_eq!(paths(PROBES), wgsl_files("shaders/probes"));
    assert!(
        wgsl_files("shaders").is_empty(),
        "WGSL files directly in shaders/"
    );
}

#[test]
fn every_pass_and_module_validates() {
    for file in all_files() {
        let assembled = assemble(file, &modules()).unwrap_or_else(|e| panic!("{e}"));
        if let Err(e) = assembled.validate() {
            panic!("{e}");
        }
    }
}

/// Names declared at the start of a line as `<prefix>name` up to `(`, `{` or a space.
fn declared_names(text: &str, prefix: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix(prefix))
        .map(|rest| rest.split(['(', '{', ' ']).next().unwrap_or("").to_string())
        .collect()
}

/// The mixed precision's engine modules stand in for the exact ones of the same name: the same
/// functions and structs, and they validate without f64 where the passes use them.
#[test]
fn mixed_engine_modules_offer_what_the_exact_ones_do() {
    for mixed in MIXED_ENGINE {
        let exact = ENGINE
            .iter()
            .find(|m| m.name() == mixed.name())
            .unwrap_or_else(|| panic!("{}: no engine module of that name", mixed.path));
        for prefix in ["fn ", "struct "] {
            let (e, m) = (
                declared_names(exact.text, prefix),
                declared_names(mixed.text, prefix),
            );
            assert!(
                e.is_subset(&m),
                "{}: {prefix}{:?} missing",
                mixed.path,
                e.difference(&m).collect::<Vec<_>>()
            );
        }
        let assembled = assemble(mixed, &modules_at(Precision::Mixed))
            .unwrap()
            .with_precision(Precision::Mixed);
        assembled.validate().unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn mixed_modules_need_no_f64() {
    for module in MIXED {
        let assembled = assemble(module, &modules())
            .unwrap()
            .with_precision(Precision::Mixed);
        assert_eq!(
            assembled.source,
            assemble(module, &modules()).unwrap().source,
            "{}: written in f32, nothing to derive",
            module.path
        );
        let (m, _) = assembled.validate().unwrap_or_else(|e| panic!("{e}"));
        assert!(m.entry_points.is_empty(), "{}: entry point", module.path);
    }
}

#[test]
fn model_modules_are_import_only() {
    for module in MODEL {
        let (m, _) = assemble(module, MODEL).unwrap().validate().unwrap();
        assert!(m.entry_points.is_empty(), "{}: entry point", module.path);
        assert!(m.global_variables.is_empty(), "{}: global", module.path);
    }
}

#[test]
fn requirements_come_first_and_once() {
    for file in all_files() {
        let a = assemble(file, &modules()).unwrap();
        let order: Vec<_> = a.segments.iter().map(|s| s.path).collect();
        assert_eq!(*order.last().unwrap(), file.path);
        let unique: BTreeSet<_> = order.iter().collect();
        assert_eq!(unique.len(), order.len(), "{order:?}");
        for (i, path) in order.iter().enumerate() {
            let module = all_files().find(|s| s.path == *path).unwrap();
            for dep in module.requires() {
                let at = order
                    .iter()
                    .position(|p| modules().iter().any(|m| m.path == *p && m.name() == dep));
                assert!(
                    at.is_some_and(|at| at < i),
                    "{path} needs {dep} first: {order:?}"
                );
            }
        }
    }
}

const TOY_MODULES: &[Source] = &[
    Source {
        path: "shaders/model/a.wgsl",
        text: "// requires: b\nfn a() -> f32 { return b(); }\n",
    },
    Source {
        path: "shaders/model/b.wgsl",
        text: "// One line of prose first.\n// requires: a\nfn b() -> f32 { return 1.0; }\n",
    },
    Source {
        path: "shaders/model/broken.wgsl",
        text: "// A module with a type error on line 4.\n\nfn ok() -> f32 { return 1.0; }\nfn bad() -> f32 { return 1u; }\n",
    },
];

#[test]
fn errors_name_the_file_and_line() {
    let pass = Source {
        path: "shaders/toy.wgsl",
        text: "// requires: broken\n@compute @workgroup_size(1)\nfn main() { _ = ok(); }\n",
    };
    let err = assemble(&pass, TOY_MODULES)
        .unwrap()
        .validate()
        .unwrap_err();
    let shown = err.to_string();
    assert!(
        shown.starts_with("shaders/model/broken.wgsl:4:"),
        "error does not point at broken.wgsl line 4:\n{shown}"
    );

    let pass = Source {
        path: "shaders/toy.wgsl",
        text: "// requires: broken\n\nfn main() { let x = ; }\n",
    };
    let shown = assemble(&pass, TOY_MODULES)
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(shown.starts_with("shaders/toy.wgsl:3:"), "{shown}");
}

#[test]
fn cycles_and_unknown_modules_are_errors() {
    let pass = Source {
        path: "shaders/toy.wgsl",
        text: "// requires: a\n",
    };
    match assemble(&pass, TOY_MODULES) {
        Err(ShaderError::Cycle(chain)) => assert_eq!(chain.len(), 3, "{chain:?}"),
        other => panic!("expected a cycle, got {other:?}"),
    }
    let pass = Source {
        path: "shaders/toy.wgsl",
        text: "// requires: nowhere\n",
    };
    let err = assemble(&pass, TOY_MODULES).unwrap_err().to_string();
    assert!(
        err.contains("shaders/toy.wgsl") && err.contains("nowhere"),
        "{err}"
    );
}

#[test]
fn requires_lines_stop_at_the_first_code_line() {
    let s = Source {
        path: "x.wgsl",
        text: "// requires: a b\n//\n// requires: c\nfn f() {}\n// requires: d\n",
    };
    assert_eq!(s.requires(), ["a", "b", "c"]);
}

#[test]
fn one_slot_chunk_sets_the_override_the_pipelines_apply() {
    let chunks = |a: &Assembled| -> u32 {
        let (module, info) = a.validate().unwrap();
        let (module, _) = a.with_overrides_applied(&module, &info, None).unwrap();
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some("SLOT_CHUNKS_IN_USE"))
            .expect("the override becomes a constant");
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref other => panic!("{other:?}"),
        }
    };
    let forces = assemble_pass("forces").unwrap();
    assert_eq!(chunks(&forces), 3);
    assert_eq!(chunks(&forces.clone().with_one_slot_chunk()), 1);
    // A pass without the engine's bindings has no such override and is left alone.
    let probe = assemble_pass("contact_law_probe")
        .unwrap()
        .with_one_slot_chunk();
    assert!(probe.overrides.is_empty());
}
