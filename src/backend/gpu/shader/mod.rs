//! Shader sources, their assembly from shared modules, and naga validation.
//!
//! WGSL has no imports, so a pass is assembled by concatenation. The convention:
//!
//! - `shaders/shared/<module>.wgsl` are import-only modules (functions, structs, constants; no
//!   bindings, no entry points). `<module>` is the name other files use to ask for it.
//! - Any shader file, shared or pass, names the modules it calls into with a line
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

use super::context::GpuContext;
use super::spirv;
use std::fmt;

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
    /// The module name: the file stem (`shaders/shared/normal.wgsl` → `normal`).
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

/// The import-only modules. A test checks this list against `shaders/shared/`.
pub const SHARED: &[Source] = &[
    wgsl!("model/math.wgsl"),
    wgsl!("model/normal.wgsl"),
    wgsl!("model/damping.wgsl"),
    wgsl!("model/pointer.wgsl"),
    wgsl!("model/rolling.wgsl"),
    wgsl!("model/sliding.wgsl"),
    wgsl!("model/twisting.wgsl"),
    wgsl!("model/wall.wgsl"),
];

/// Engine modules: import-only like the shared ones, but they may declare the engine's bindings
/// (`bindings`) and use them (`interaction`, `cells`). A test checks this list against
/// `shaders/engine/`.
pub const ENGINE: &[Source] = &[
    wgsl!("engine/bindings.wgsl"),
    wgsl!("engine/cells.wgsl"),
    wgsl!("engine/interaction.wgsl"),
    wgsl!("engine/owner.wgsl"),
    wgsl!("engine/wall_sums.wgsl"),
];

/// Passes: files with entry points. A test checks this list against `shaders/`.
pub const PASSES: &[Source] = &[
    wgsl!("probes/contact_law_probe.wgsl"),
    wgsl!("passes/integrate.wgsl"),
    wgsl!("passes/neighbours.wgsl"),
    wgsl!("passes/contacts.wgsl"),
    wgsl!("passes/forces.wgsl"),
    wgsl!("passes/walls.wgsl"),
    wgsl!("passes/reduce.wgsl"),
];

/// Every module a `// requires:` line may name: the shared ones, then the engine's.
pub fn modules() -> Vec<Source> {
    SHARED.iter().chain(ENGINE).copied().collect()
}

/// naga capabilities the shaders may use. They must stay within what
/// [`super::context::REQUIRED_FEATURES`] asks of the device.
pub const CAPABILITIES: naga::valid::Capabilities = naga::valid::Capabilities::FLOAT64;

/// A stretch of the assembled text that came from one file.
#[derive(Clone, Copy, Debug)]
struct Segment {
    path: &'static str,
    /// 1-based line of the assembled text holding the file's first line.
    first_line: u32,
    lines: u32,
}

/// A pass (or a shared module with its requirements) as one WGSL text.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// Path of the file assembled for (the pass, or the shared module).
    pub path: &'static str,
    pub source: String,
    segments: Vec<Segment>,
}

/// The line of shaders/engine/bindings.wgsl that [`Assembled::with_one_slot_chunk`] rewrites.
const SLOT_CHUNKS_LINE: &str = "const SLOT_CHUNKS_IN_USE: u32 = 3u;";

impl Assembled {
    /// The same pass compiled for per-slot arrays held in one binding (see
    /// `Sizes::one_slot_chunk`): one line changes, so error locations stay as they are. A pass
    /// without the engine's bindings is returned unchanged.
    pub fn with_one_slot_chunk(mut self) -> Self {
        if self.source.contains(SLOT_CHUNKS_LINE) {
            self.source = self
                .source
                .replace(SLOT_CHUNKS_LINE, "const SLOT_CHUNKS_IN_USE: u32 = 1u;");
        }
        self
    }

    /// File and 1-based line of a 1-based line of the assembled text; `None` for marker lines.
    pub fn locate(&self, line: u32) -> Option<(&'static str, u32)> {
        self.segments
            .iter()
            .find(|s| line >= s.first_line && line < s.first_line + s.lines)
            .map(|s| (s.path, line - s.first_line + 1))
    }

    /// Parses and validates with naga, reporting errors by file and line.
    pub fn validate(&self) -> Result<(naga::Module, naga::valid::ModuleInfo), ShaderError> {
        let module = naga::front::wgsl::parse_str(&self.source).map_err(|e| {
            self.error(
                "parse",
                e.location(&self.source),
                e.message().to_string(),
                e.emit_to_string_with_path(&self.source, &self.report_path()),
            )
        })?;
        let mut validator =
            naga::valid::Validator::new(naga::valid::ValidationFlags::all(), CAPABILITIES);
        let info = validator.validate(&module).map_err(|e| {
            let mut message = e.as_inner().to_string();
            let mut cause: Option<&dyn std::error::Error> = std::error::Error::source(e.as_inner());
            while let Some(c) = cause {
                message.push_str(": ");
                message.push_str(&c.to_string());
                cause = c.source();
            }
            self.error(
                "validation",
                e.location(&self.source),
                message,
                e.emit_to_string_with_path(&self.source, &self.report_path()),
            )
        })?;
        Ok((module, info))
    }

    /// Validates with naga (for errors by file and line) and makes a module in the context's
    /// [`FloatMode`].
    pub fn create_module(&self, ctx: &GpuContext) -> Result<wgpu::ShaderModule, ShaderError> {
        self.create_module_as(ctx, ctx.float_mode)
    }

    /// As [`Assembled::create_module`], in the given mode (the parity test compares both).
    pub fn create_module_as(
        &self,
        ctx: &GpuContext,
        mode: FloatMode,
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        self.create_module_for(ctx, mode, None)
    }

    /// A module for one entry point (`Some`) or all of them, in the given mode. In the exact
    /// mode a module for one entry point declares only the bindings that entry point uses.
    pub fn create_module_for(
        &self,
        ctx: &GpuContext,
        mode: FloatMode,
        entry: Option<&str>,
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        let (module, info) = self.validate()?;
        match mode {
            FloatMode::Relaxed => {
                Ok(ctx
                    .device
                    .create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(self.path),
                        source: wgpu::ShaderSource::Wgsl(self.source.as_str().into()),
                    }))
            }
            FloatMode::Exact => {
                if ctx.float_mode != FloatMode::Exact {
                    return Err(ShaderError::ExactUnavailable(ctx.summary().name));
                }
                let words =
                    spirv::exact_spirv(&module, &info, entry).map_err(|e| ShaderError::Spirv {
                        path: self.path,
                        message: e.to_string(),
                    })?;
                let entry_points: Vec<_> = module
                    .entry_points
                    .iter()
                    .filter(|ep| entry.is_none_or(|name| ep.name == name))
                    .map(|ep| wgpu::PassthroughShaderEntryPoint {
                        name: ep.name.clone().into(),
                        workgroup_size: ep.workgroup_size.into(),
                    })
                    .collect();
                // SAFETY: the words are naga's SPIR-V for a module naga has just validated with
                // CAPABILITIES, which the device's features cover; the added NoContraction
                // decorations only forbid rewrites and change no type, id or control flow.
                // What passthrough skips is wgpu's check of the shader's bindings against the
                // pipeline layout, which the kernels' explicit layouts must therefore match.
                Ok(unsafe {
                    ctx.device.create_shader_module_passthrough(
                        wgpu::ShaderModuleDescriptorPassthrough {
                            label: Some(self.path),
                            entry_points: entry_points.into(),
                            spirv: Some(words.into()),
                            ..Default::default()
                        },
                    )
                })
            }
        }
    }

    /// The name naga's report gives the assembled text: its line numbers are not a file's.
    fn report_path(&self) -> String {
        format!("<{} assembled>", self.path)
    }

    fn error(
        &self,
        stage: &'static str,
        location: Option<naga::SourceLocation>,
        message: String,
        report: String,
    ) -> ShaderError {
        let (file, line, column, text) = match location {
            Some(loc) => {
                let text = self
                    .source
                    .lines()
                    .nth(loc.line_number as usize - 1)
                    .unwrap_or("")
                    .to_string();
                match self.locate(loc.line_number) {
                    Some((file, line)) => (file, line, loc.line_position, text),
                    None => (self.path, 0, 0, text),
                }
            }
            None => (self.path, 0, 0, String::new()),
        };
        ShaderError::Naga(Box::new(NagaError {
            stage,
            assembled_for: self.path,
            file,
            line,
            column,
            message,
            text,
            report,
        }))
    }
}

/// What can go wrong between the WGSL files and a module wgpu accepts.
#[derive(Debug)]
pub enum ShaderError {
    UnknownPass(String),
    /// A `// requires:` line names no file in `shaders/shared/`.
    UnknownModule {
        requested_by: &'static str,
        name: String,
    },
    /// Modules that require each other, in the order found.
    Cycle(Vec<&'static str>),
    /// naga could not write SPIR-V for a module it validated.
    Spirv {
        path: &'static str,
        message: String,
    },
    /// [`FloatMode::Exact`] asked of a device without Vulkan SPIR-V passthrough.
    ExactUnavailable(String),
    /// naga rejected the assembled text.
    Naga(Box<NagaError>),
}

/// A naga parse or validation error, located in the file a person edits.
#[derive(Debug)]
pub struct NagaError {
    /// "parse" or "validation".
    pub stage: &'static str,
    pub assembled_for: &'static str,
    /// `file:line:column` is where to look (line 0 when naga gave no location).
    pub file: &'static str,
    pub line: u32,
    pub column: u32,
    pub message: String,
    /// The offending line.
    pub text: String,
    /// naga's own report, with line numbers of the assembled text.
    pub report: String,
}

impl fmt::Display for ShaderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShaderError::UnknownPass(name) => write!(f, "no shader pass named `{name}`"),
            ShaderError::UnknownModule { requested_by, name } => write!(
                f,
                "{requested_by}: requires `{name}`, but there is no shaders/shared/{name}.wgsl"
            ),
            ShaderError::Cycle(chain) => {
                write!(
                    f,
                    "shared modules require each other: {}",
                    chain.join(" → ")
                )
            }
            ShaderError::Spirv { path, message } => {
                write!(f, "{path}: SPIR-V output failed: {message}")
            }
            ShaderError::ExactUnavailable(adapter) => write!(
                f,
                "{adapter}: no SPIR-V passthrough (Vulkan only), so no bit-exact float mode"
            ),
            ShaderError::Naga(e) => write!(
                f,
                "{}:{}:{}: WGSL {} error (assembling {}): {}\n    {}\n\n\
                 naga's report on the assembled text:\n{}",
                e.file,
                e.line,
                e.column,
                e.stage,
                e.assembled_for,
                e.message,
                e.text.trim(),
                e.report
            ),
        }
    }
}

impl std::error::Error for ShaderError {}

/// Assembles the registered pass called `name` (file stem, e.g. `contact_law_probe`).
pub fn assemble_pass(name: &str) -> Result<Assembled, ShaderError> {
    let pass = PASSES
        .iter()
        .find(|p| p.name() == name)
        .ok_or_else(|| ShaderError::UnknownPass(name.to_string()))?;
    assemble(pass, &modules())
}

/// Assembles `file` with the modules it requires, taken from `shared`.
///
/// Works for a shared module too (validating one alone checks it and its requirements).
pub fn assemble(file: &Source, shared: &[Source]) -> Result<Assembled, ShaderError> {
    let mut order = Vec::new();
    let mut visiting = Vec::new();
    for name in file.requires() {
        visit(file, name, shared, &mut order, &mut visiting)?;
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
        segments.push(Segment {
            path: part.path,
            first_line: line,
            lines,
        });
        line += lines;
        source.push('\n');
        line += 1;
    }
    Ok(Assembled {
        path: file.path,
        source,
        segments,
    })
}

/// Depth-first: a module's requirements go in before the module.
fn visit<'a>(
    requested_by: &Source,
    name: &str,
    shared: &'a [Source],
    order: &mut Vec<&'a Source>,
    visiting: &mut Vec<&'static str>,
) -> Result<(), ShaderError> {
    let module =
        shared
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
        visit(module, dep, shared, order, visiting)?;
    }
    visiting.pop();
    order.push(module);
    Ok(())
}

#[cfg(test)]
mod tests {
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

    #[test]
    fn every_shader_file_is_registered() {
        let shared: BTreeSet<String> = SHARED.iter().map(|s| s.path.to_string()).collect();
        let passes: BTreeSet<String> = PASSES.iter().map(|s| s.path.to_string()).collect();
        let engine: BTreeSet<String> = ENGINE.iter().map(|s| s.path.to_string()).collect();
        assert_eq!(shared, wgsl_files("shaders/model"));
        assert_eq!(engine, wgsl_files("shaders/engine"));
        let mut on_disk = wgsl_files("shaders/passes");
        on_disk.extend(wgsl_files("shaders/probes"));
        assert_eq!(passes, on_disk);
        assert!(
            wgsl_files("shaders").is_empty(),
            "WGSL files directly in shaders/"
        );
    }

    #[test]
    fn every_pass_and_shared_module_validates() {
        for file in PASSES.iter().chain(SHARED).chain(ENGINE) {
            let assembled = assemble(file, &modules()).unwrap_or_else(|e| panic!("{e}"));
            if let Err(e) = assembled.validate() {
                panic!("{e}");
            }
        }
    }

    #[test]
    fn shared_modules_are_import_only() {
        for module in SHARED {
            let (m, _) = assemble(module, SHARED).unwrap().validate().unwrap();
            assert!(m.entry_points.is_empty(), "{}: entry point", module.path);
            assert!(m.global_variables.is_empty(), "{}: global", module.path);
        }
    }

    #[test]
    fn requirements_come_first_and_once() {
        for file in PASSES.iter().chain(SHARED).chain(ENGINE) {
            let a = assemble(file, &modules()).unwrap();
            let order: Vec<_> = a.segments.iter().map(|s| s.path).collect();
            assert_eq!(*order.last().unwrap(), file.path);
            let unique: BTreeSet<_> = order.iter().collect();
            assert_eq!(unique.len(), order.len(), "{order:?}");
            for (i, path) in order.iter().enumerate() {
                let module = PASSES
                    .iter()
                    .chain(SHARED)
                    .chain(ENGINE)
                    .find(|s| s.path == *path)
                    .unwrap();
                for dep in module.requires() {
                    let at = order.iter().position(|p| {
                        SHARED
                            .iter()
                            .chain(ENGINE)
                            .any(|m| m.path == *p && m.name() == dep)
                    });
                    assert!(
                        at.is_some_and(|at| at < i),
                        "{path} needs {dep} first: {order:?}"
                    );
                }
            }
        }
    }

    const TOY_SHARED: &[Source] = &[
        Source {
            path: "shaders/shared/a.wgsl",
            text: "// requires: b\nfn a() -> f32 { return b(); }\n",
        },
        Source {
            path: "shaders/shared/b.wgsl",
            text: "// One line of prose first.\n// requires: a\nfn b() -> f32 { return 1.0; }\n",
        },
        Source {
            path: "shaders/shared/broken.wgsl",
            text: "// A module with a type error on line 4.\n\nfn ok() -> f32 { return 1.0; }\nfn bad() -> f32 { return 1u; }\n",
        },
    ];

    #[test]
    fn errors_name_the_file_and_line() {
        let pass = Source {
            path: "shaders/toy.wgsl",
            text: "// requires: broken\n@compute @workgroup_size(1)\nfn main() { _ = ok(); }\n",
        };
        let err = assemble(&pass, TOY_SHARED).unwrap().validate().unwrap_err();
        let shown = err.to_string();
        assert!(
            shown.starts_with("shaders/shared/broken.wgsl:4:"),
            "error does not point at broken.wgsl line 4:\n{shown}"
        );

        let pass = Source {
            path: "shaders/toy.wgsl",
            text: "// requires: broken\n\nfn main() { let x = ; }\n",
        };
        let shown = assemble(&pass, TOY_SHARED)
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
        match assemble(&pass, TOY_SHARED) {
            Err(ShaderError::Cycle(chain)) => assert_eq!(chain.len(), 3, "{chain:?}"),
            other => panic!("expected a cycle, got {other:?}"),
        }
        let pass = Source {
            path: "shaders/toy.wgsl",
            text: "// requires: nowhere\n",
        };
        let err = assemble(&pass, TOY_SHARED).unwrap_err().to_string();
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
}
