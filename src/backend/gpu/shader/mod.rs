//! Shader sources, their assembly from modules, and naga validation.
//!
//! The WGSL tree mirrors the Rust one: `shaders/model/` are the twins of `src/model/` (the
//! contact law), `shaders/engine/` the engine's bindings and the contact interaction (twin of
//! `src/state/interaction.rs`), `shaders/passes/` the entry points of the step (twins of the
//! CPU backend's passes), `shaders/probes/` test-only entry points.
//!
//! WGSL has no imports, so a pass is assembled by concatenation. The convention:
//!
//! - `shaders/mixed/<module>.wgsl` are the mixed precision mode's f32 representations (twins of
//!   `src/mixed/`), import-only like the model's.
//! - `shaders/model/<module>.wgsl` are import-only modules (functions, structs, constants; no
//!   bindings, no entry points). `<module>` is the name other files use to ask for it.
//! - Any shader file, module or pass, names the modules it calls into with a line
//!   `// requires: normal rolling sliding` in its leading comment block (several such lines add
//!   up). Requirements are transitive: a pass lists what it calls itself, not what those modules
//!   call.
//! - A pass's source is its requirements in dependency order, each exactly once, followed by
//!   the pass itself. Every file is included verbatim behind a `// ---- <path> ----` marker, so
//!   the assembled text reads like the files it came from.
//!
//! A validated pass reaches the driver in one of two [`FloatMode`]s; `Exact` is the one that keeps
//! the f64 twins bit-identical (see `spirv.rs` for why WGSL alone does not).
//!
//! Every file is embedded with `include_str!` (the binary needs no `shaders/` directory at run
//! time, and cargo rebuilds when a shader changes). naga reports errors against the assembled
//! text; [`Assembled::locate`] maps them back to the file and line a person edits.
//!
//! Here: the registry of files and the assembly; `assembled` validates and compiles an
//! assembled text, `error` says what went wrong and where.

mod assembled;
mod error;
mod precision;
#[cfg(test)]
mod tests;

pub use assembled::Assembled;
pub use error::{NagaError, ShaderError};
pub use precision::Precision;

/// How a validated shader reaches the driver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FloatMode {
    /// naga's SPIR-V with every float operation decorated `NoContraction`, through wgpu's
    /// SPIR-V passthrough (Vulkan): f64 results equal the CPU twins' to the bit. wgpu cannot
    /// reflect such a module, so its pipelines need explicit layouts.
    Exact,
    /// WGSL through wgpu: the driver may fuse multiplies and adds and reassociate, so results
    /// differ from the CPU's by ulps, and by √ulp where a formula is ill-conditioned.
    Relaxed,
}

/// One WGSL file: its path below the crate root and its text.
#[derive(Clone, Copy, Debug)]
pub struct Source {
    pub path: &'static str,
    pub text: &'static str,
}

impl Source {
    /// The module name: the file stem (`shaders/model/normal.wgsl` → `normal`).
    pub fn name(&self) -> &'static str {
        let file = self.path.rsplit('/').next().unwrap_or(self.path);
        file.strip_suffix(".wgsl").unwrap_or(file)
    }

    /// Modules named on `// requires:` lines of the leading comment block, in order.
    pub fn requires(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        for line in self.text.lines().map(str::trim) {
            if line.is_empty() {
                continue;
            }
            let Some(comment) = line.strip_prefix("//") else {
                break;
            };
            if let Some(list) = comment.trim().strip_prefix("requires:") {
                names.extend(list.split_whitespace());
            }
        }
        names
    }
}

macro_rules! wgsl {
    ($path:literal) => {
        Source {
            path: concat!("shaders/", $path),
            text: include_str!(concat!("../../../../shaders/", $path)),
        }
    };
}

/// The import-only modules of the contact law, twins of `src/model/`. A test checks this list
/// against `shaders/model/`.
pub const MODEL: &[Source] = &[
    wgsl!("model/math.wgsl"),
    wgsl!("model/normal.wgsl"),
    wgsl!("model/damping.wgsl"),
    wgsl!("model/pointer.wgsl"),
    wgsl!("model/rolling.wgsl"),
    wgsl!("model/sliding.wgsl"),
    wgsl!("model/twisting.wgsl"),
    wgsl!("model/wall.wgsl"),
];

/// The mixed precision mode's representations, written in f32: twins of `src/mixed/`
/// (`math32` of glam's Vec3, as `math` is of DVec3). A test checks this list against
/// `shaders/mixed/`.
pub const MIXED: &[Source] = &[
    wgsl!("mixed/math32.wgsl"),
    wgsl!("mixed/double_f32.wgsl"),
    wgsl!("mixed/split.wgsl"),
    wgsl!("mixed/split_pointer.wgsl"),
];

/// Engine modules: import-only like the model's, but they may declare the engine's bindings
/// (`bindings`) and use them (`interaction`, `cells`). A test checks this list against
/// `shaders/engine/`.
pub const ENGINE: &[Source] = &[
    wgsl!("engine/accumulators.wgsl"),
    wgsl!("engine/bindings.wgsl"),
    wgsl!("engine/cells.wgsl"),
    wgsl!("engine/interaction.wgsl"),
    wgsl!("engine/owner.wgsl"),
    wgsl!("engine/pointers.wgsl"),
    wgsl!("engine/positions.wgsl"),
    wgsl!("engine/wall_sums.wgsl"),
];

/// Engine modules of the mixed precision, each in place of the engine module of the same
/// name ([`modules_at`]). A test checks this list against `shaders/mixed_engine/`.
pub const MIXED_ENGINE: &[Source] = &[
    wgsl!("mixed_engine/accumulators.wgsl"),
    wgsl!("mixed_engine/pointers.wgsl"),
    wgsl!("mixed_engine/positions.wgsl"),
];

/// Passes: the engine's entry points, in files named as the CPU backend's passes. A test checks
/// this list against `shaders/passes/`.
pub const PASSES: &[Source] = &[
    wgsl!("passes/integrate.wgsl"),
    wgsl!("passes/neighbours.wgsl"),
    wgsl!("passes/contacts.wgsl"),
    wgsl!("passes/forces.wgsl"),
    wgsl!("passes/walls.wgsl"),
    wgsl!("passes/reduce.wgsl"),
    wgsl!("passes/rows.wgsl"),
];

/// Probes: entry points that only tests run (the contact law on recorded inputs). A test checks
/// this list against `shaders/probes/`.
pub const PROBES: &[Source] = &[
    wgsl!("probes/contact_law_probe.wgsl"),
    wgsl!("probes/mixed_probe.wgsl"),
];

/// Every module a `// requires:` line may name: the model's, the engine's, the mixed mode's.
pub fn modules() -> Vec<Source> {
    MODEL.iter().chain(ENGINE).chain(MIXED).copied().collect()
}

/// The modules a pass is assembled from at `precision`: [`modules`], with the mixed
/// precision's engine modules first (the first of a name is the one taken).
pub fn modules_at(precision: Precision) -> Vec<Source> {
    let first: &[Source] = match precision {
        Precision::Exact => &[],
        Precision::Mixed => MIXED_ENGINE,
    };
    first.iter().copied().chain(modules()).collect()
}

/// naga capabilities the f64 sources may use ([`Precision::Exact`]); the mixed texts use
/// none ([`Precision::capabilities`]).
pub const CAPABILITIES: naga::valid::Capabilities = naga::valid::Capabilities::FLOAT64;

/// The engine's bindings module (shaders/engine/bindings.wgsl with its requirements) at
/// `precision`, as naga reads it: what the host's layouts are derived from and checked against.
pub(crate) fn bindings_module(precision: Precision) -> Result<naga::Module, ShaderError> {
    let bindings = ENGINE.iter().find(|m| m.name() == "bindings").unwrap();
    let assembled = assemble(bindings, &modules_at(precision))?.with_precision(precision);
    Ok(assembled.validate()?.0)
}

/// [`bindings_module`] in the exact precision, for the tests that hold the host side to it.
#[cfg(test)]
pub(crate) fn engine_module() -> naga::Module {
    bindings_module(Precision::Exact).unwrap()
}

/// Assembles the registered pass or probe called `name` (file stem, e.g. `contact_law_probe`).
pub fn assemble_pass(name: &str) -> Result<Assembled, ShaderError> {
    assemble_pass_at(name, Precision::Exact)
}

/// [`assemble_pass`] at `precision`: its modules ([`modules_at`]) and its text
/// ([`Assembled::with_precision`]).
pub fn assemble_pass_at(name: &str, precision: Precision) -> Result<Assembled, ShaderError> {
    let pass = PASSES
        .iter()
        .chain(PROBES)
        .find(|p| p.name() == name)
        .ok_or_else(|| ShaderError::UnknownPass(name.to_string()))?;
    Ok(assemble(pass, &modules_at(precision))?.with_precision(precision))
}

/// Assembles `file` with the modules it requires, taken from `modules`.
///
/// Works for a module too (validating one alone checks it and its requirements).
pub fn assemble(file: &Source, modules: &[Source]) -> Result<Assembled, ShaderError> {
    let mut order = Vec::new();
    let mut visiting = Vec::new();
    for name in file.requires() {
        visit(file, name, modules, &mut order, &mut visiting)?;
    }
    let mut source = String::new();
    let mut segments = Vec::new();
    let mut line = 1u32;
    for part in order.iter().copied().chain(std::iter::once(file)) {
        source.push_str(&format!("// ---- {} ----\n", part.path));
        line += 1;
        source.push_str(part.text);
        if !part.text.ends_with('\n') {
            source.push('\n');
        }
        let lines = part.text.lines().count() as u32;
        segments.push(assembled::Segment {
            path: part.path,
            first_line: line,
            lines,
        });
        line += lines;
        source.push('\n');
        line += 1;
    }
    Ok(Assembled::new(file.path, source, segments))
}

/// Depth-first: a module's requirements go in before the module.
fn visit<'a>(
    requested_by: &Source,
    name: &str,
    modules: &'a [Source],
    order: &mut Vec<&'a Source>,
    visiting: &mut Vec<&'static str>,
) -> Result<(), ShaderError> {
    let module =
        modules
            .iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| ShaderError::UnknownModule {
                requested_by: requested_by.path,
                name: name.to_string(),
            })?;
    if order.iter().any(|m| m.path == module.path) {
        return Ok(());
    }
    if visiting.contains(&module.path) {
        let mut chain = visiting.clone();
        chain.push(module.path);
        return Err(ShaderError::Cycle(chain));
    }
    visiting.push(module.path);
    for dep in module.requires() {
        visit(module, dep, modules, order, visiting)?;
    }
    visiting.pop();
    order.push(module);
    Ok(())
}
