//! An assembled pass: validation with naga (errors by file and line), and the module wgpu runs
//! in either float mode.

use super::error::{NagaError, ShaderError};
use super::{FloatMode, Precision};
use crate::backend::gpu::context::GpuContext;
use crate::backend::gpu::spirv;

/// A stretch of the assembled text that came from one file.
#[derive(Clone, Copy, Debug)]
pub(super) struct Segment {
    pub(super) path: &'static str,
    /// 1-based line of the assembled text holding the file's first line.
    pub(super) first_line: u32,
    pub(super) lines: u32,
}

/// A pass (or a module with its requirements) as one WGSL text.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// Path of the file assembled for (the pass, or the module).
    pub path: &'static str,
    pub source: String,
    pub(super) segments: Vec<Segment>,
    /// The arithmetic width of `source` (assembled as f64; see [`Assembled::with_precision`]).
    pub precision: Precision,
    /// Values of the text's `override` constants for the pipelines made from it (the others
    /// keep their defaults).
    pub overrides: Vec<(&'static str, f64)>,
}

/// The pipeline-overridable constant of shaders/engine/bindings.wgsl that
/// [`Assembled::with_one_slot_chunk`] sets.
const SLOT_CHUNKS_IN_USE: &str = "SLOT_CHUNKS_IN_USE";

impl Assembled {
    pub(super) fn new(path: &'static str, source: String, segments: Vec<Segment>) -> Self {
        Assembled {
            path,
            source,
            segments,
            precision: Precision::Exact,
            overrides: Vec::new(),
        }
    }

    /// The same pass at `precision`: the mixed text is derived from the f64 one token by
    /// token (`shader::precision`), so error locations stay as they are.
    pub fn with_precision(mut self, precision: Precision) -> Self {
        if self.precision != precision {
            assert_eq!(
                self.precision,
                Precision::Exact,
                "{}: already derived",
                self.path
            );
            self.source = precision.apply(&self.source);
            self.precision = precision;
        }
        self
    }

    /// The same pass for per-slot arrays held in one binding (see `Sizes::one_slot_chunk`):
    /// the `override` SLOT_CHUNKS_IN_USE is 1 in its pipelines, and the driver folds the chunk
    /// selection away. A pass without the engine's bindings is returned unchanged.
    pub fn with_one_slot_chunk(mut self) -> Self {
        if self
            .source
            .contains(&format!("override {SLOT_CHUNKS_IN_USE}:"))
        {
            self.overrides.push((SLOT_CHUNKS_IN_USE, 1.0));
        }
        self
    }

    /// The overrides as naga takes them.
    fn pipeline_constants(&self) -> naga::back::PipelineConstants {
        self.overrides
            .iter()
            .map(|(name, value)| (name.to_string(), *value))
            .collect()
    }

    /// The module with every `override` replaced by its value (naga's writers take no
    /// overrides), for `entry` alone or for all entry points.
    pub fn with_overrides_applied<'a>(
        &self,
        module: &'a naga::Module,
        info: &'a naga::valid::ModuleInfo,
        entry: Option<&str>,
    ) -> Result<(naga::Module, naga::valid::ModuleInfo), ShaderError> {
        let (module, info) = naga::back::pipeline_constants::process_overrides(
            module,
            info,
            entry.map(|e| (naga::ShaderStage::Compute, e)),
            &self.pipeline_constants(),
        )
        .map_err(|e| ShaderError::Spirv {
            path: self.path,
            message: format!("overrides: {e}"),
        })?;
        Ok((module.into_owned(), info.into_owned()))
    }

    /// The same pass with every `var<uniform>` declared as read-only storage (what
    /// `backend::gpu::quirks` says some drivers need): the same data at the same offsets, so
    /// the same bits, and only columns of error locations move.
    pub fn with_storage_uniforms(mut self) -> Self {
        self.source = self.source.replace("var<uniform> ", "var<storage, read> ");
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
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            self.precision.capabilities(),
        );
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
        if self.precision == Precision::Exact && !ctx.shader_f64 {
            return Err(ShaderError::F64Unavailable {
                path: self.path,
                adapter: ctx.summary().name,
            });
        }
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
                let (module, info) = self.with_overrides_applied(&module, &info, entry)?;
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
                // its precision's capabilities, which the device's features cover; the added NoContraction
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
