//! GPU backend: device setup, shader assembly and validation, the host encodings of the values
//! the WGSL twins take, and the engine (buffers, kernels, step script).

pub mod buffers;
pub mod context;
pub mod engine;
pub mod kernels;
pub mod layout;
pub mod shader;
pub mod spirv;

#[cfg(test)]
mod twins;
