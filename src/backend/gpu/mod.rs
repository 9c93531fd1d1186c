//! GPU backend: device setup, shader assembly and validation, the host encodings of the values
//! the WGSL twins take, and the engine (buffers, kernels, step script).
//!
//! A leaf: it steps a `State` under the `Engine` contract and uses nothing of the CPU backend;
//! `twins` holds its WGSL to the Rust twins in `model`, `state` and `backend::cpu` by name.

pub mod buffers;
pub mod context;
pub mod engine;
pub mod interface;
pub mod kernels;
pub mod layout;
pub mod quirks;
mod runtime_dir;
pub mod shader;
pub mod spirv;
pub mod transcode;

#[cfg(test)]
mod twins;
