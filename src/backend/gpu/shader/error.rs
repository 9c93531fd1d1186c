//! What can go wrong between the WGSL files and a module wgpu accepts, located in the file a
//! person edits.

use std::fmt;

/// What can go wrong between the WGSL files and a module wgpu accepts.
#[derive(Debug)]
pub enum ShaderError {
    UnknownPass(String),
    /// A `// requires:` line names no file in `shaders/model/` or `shaders/engine/`.
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
    /// An f64 pass ([`super::Precision::Exact`]) for a device made without `SHADER_F64`.
    F64Unavailable {
        path: &'static str,
        adapter: String,
    },
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
                "{requested_by}: requires `{name}`, but there is no shaders/model/{name}.wgsl \
                 or shaders/engine/{name}.wgsl"
            ),
            ShaderError::Cycle(chain) => {
                write!(f, "modules require each other: {}", chain.join(" → "))
            }
            ShaderError::Spirv { path, message } => {
                write!(f, "{path}: SPIR-V output failed: {message}")
            }
            ShaderError::ExactUnavailable(adapter) => write!(
                f,
                "{adapter}: no SPIR-V passthrough (Vulkan only), so no bit-exact float mode"
            ),
            ShaderError::F64Unavailable { path, adapter } => write!(
                f,
                "{path}: f64 pass for a device without SHADER_F64 ({adapter}); compile it at \
                 Precision::Mixed"
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
