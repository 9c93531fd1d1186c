//! GPU backend: device setup, shader assembly and validation, and the host encodings of the
//! values the WGSL twins of `model/` take.

pub mod context;
pub mod layout;
pub mod shader;
pub mod spirv;

#[cfg(test)]
mod twins;
