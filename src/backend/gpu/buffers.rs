//! The engine's device buffers, one per binding of shaders/engine/bindings.wgsl (same numbers,
//! same order), and what they cost per monomer.
//!
//! Buffers are data only; the pipelines that use them are in `kernels.rs`. Everything is created
//! once for a fixed N and slot counts; nothing is reallocated while the engine runs.

use super::layout::{
    GpuParams, GpuWall, ARGS_REBUILD, DIAG_SIZE, EVENT_LISTS, FLAG_COUNT, INCOMING_CAPACITY,
    MAX_WALLS, NEIGHBOUR_CAPACITY, REDUCE_BLOCK, ROW_PARTIALS, ROW_SUMS, SLOT_CHUNKS, TALLY_STRIDE,
    WORK_LISTS,
};
use std::fmt;

/// Bytes of one vec4<f64>.
const VEC4: u64 = 32;

/// Binding names in binding order (index = binding number of bindings.wgsl). A per-slot
/// vector array is [`SLOT_CHUNKS`] bindings, `<array>_0` … `<array>_2`.
pub const BINDINGS: [&str; 54] = [
    "params",
    "walls",
    "position",
    "velocity",
    "angular_velocity",
    "force",
    "torque",
    "damping_force",
    "aux",
    "tally",
    "pair_n1_0",
    "pair_n1_1",
    "pair_n1_2",
    "pair_n2_0",
    "pair_n2_1",
    "pair_n2_2",
    "pair_partner",
    "pair_count",
    "pair_result_a_0",
    "pair_result_a_1",
    "pair_result_a_2",
    "pair_result_b_0",
    "pair_result_b_1",
    "pair_result_b_2",
    "pair_result_c_0",
    "pair_result_c_1",
    "pair_result_c_2",
    "wall_n1",
    "wall_anchor",
    "wall_id",
    "wall_count",
    "wall_force",
    "incoming",
    "incoming_count",
    "bucket_count",
    "bucket_items",
    "partials",
    "flags",
    "diag",
    "neighbour_list",
    "neighbour_count",
    "reference_position",
    "work_list",
    "work",
    "work_args",
    "moving_walls",
    "wall_table",
    "contact_list",
    "wall_damping",
    "wall_torque",
    "pair_tests",
    "row_data",
    "row_profile_data",
    "row_bits",
];

/// Bindings that are another binding's buffer under a second declaration: (alias, buffer).
/// `walls` is declared three ways (bindings.wgsl): uniform for a wall index the same in every
/// invocation, read-only storage (`wall_table`) for a wall index that differs between
/// invocations, and writable storage (`moving_walls`) for the drift, which may not bind it
/// otherwise in the same dispatch.
pub const ALIASES: [(&str, &str); 2] = [("moving_walls", "walls"), ("wall_table", "walls")];

/// The most bindings one pass uses (each pass binds only what its entry point reads or
/// writes; `kernels::tests` derives this from the shaders with naga).
pub const MAX_BINDINGS_PER_PASS: u32 = 27;

// lavapipe binds 32 storage buffers per stage, the least of the Vulkan adapters with f64.
const _: () = assert!(MAX_BINDINGS_PER_PASS <= 32);

/// Sizes of the engine's arrays for one problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sizes {
    pub monomers: usize,
    pub walls: usize,
    pub pair_slots: usize,
    pub wall_slots: usize,
    /// Buckets of the cell hash table (a power of two, ≥ 2N).
    pub table: usize,
    /// Ids per bucket.
    pub bucket_capacity: usize,
    /// Per-slot arrays over three bindings even where they fit one (what N > 349 525 needs
    /// with 12 slots); tests use it to hold that layout to the other.
    pub split_slots: bool,
}

/// Ids one bucket of the cell table holds. Cells have edge 2.2r, so a cell holds at most ~6
/// monomers at φ = 0.74 and a bucket a few more where hashed cells share it.
pub const DEFAULT_BUCKET_CAPACITY: usize = 16;

/// Vectors one binding of a per-slot array holds when a single binding is used: 128 MiB (the
/// storage binding size every adapter offers, wgpu's default) of vec4<f64>.
pub const ONE_CHUNK_CAPACITY: usize = (128 << 20) / VEC4 as usize;

impl Sizes {
    pub fn new(monomers: usize, walls: usize, pair_slots: usize, wall_slots: usize) -> Self {
        Sizes {
            monomers,
            walls,
            pair_slots,
            wall_slots,
            table: (2 * monomers.max(1)).next_power_of_two(),
            bucket_capacity: DEFAULT_BUCKET_CAPACITY,
            split_slots: false,
        }
    }

    /// Whether every per-slot array fits its first binding. The kernels are then compiled
    /// with one chunk and the chunk selection folds away: lavapipe runs both sides of every
    /// branch, so three-way selection costs three loads per access.
    pub fn one_slot_chunk(&self) -> bool {
        !self.split_slots && self.monomers * self.pair_slots <= ONE_CHUNK_CAPACITY
    }

    /// Vectors in each binding of a per-slot array: all N · pair_slots slots in the first
    /// binding where they fit ([`Sizes::one_slot_chunk`]; the other bindings then hold one
    /// unused vector, since no binding may be empty), else spread evenly over [`SLOT_CHUNKS`].
    pub fn slot_chunk(&self) -> usize {
        let slots = self.monomers * self.pair_slots;
        if self.one_slot_chunk() {
            slots.max(1)
        } else {
            slots.div_ceil(SLOT_CHUNKS)
        }
    }

    /// Bytes of chunk binding `c` of a per-slot vector array.
    fn chunk_bytes(&self, c: usize) -> u64 {
        let used = if c == 0 || !self.one_slot_chunk() {
            self.slot_chunk()
        } else {
            1
        };
        used as u64 * VEC4
    }

    /// Bytes of every binding, in binding order.
    pub fn binding_bytes(&self) -> [u64; 54] {
        let n = self.monomers as u64;
        let ws = self.wall_slots as u64;
        let ps = self.pair_slots as u64;
        let chunk = |c: usize| self.chunk_bytes(c);
        let blocks = self.monomers.div_ceil(REDUCE_BLOCK) as u64;
        [
            std::mem::size_of::<GpuParams>() as u64,
            // The uniform declaration has room for every wall the diagnostics can hold.
            MAX_WALLS as u64 * std::mem::size_of::<GpuWall>() as u64,
            n * VEC4,
            n * VEC4,
            n * VEC4,
            n * VEC4,
            n * VEC4,
            n * VEC4,
            n * VEC4,
            n * TALLY_STRIDE as u64 * 8,
            chunk(0),
            chunk(1),
            chunk(2),
            chunk(0),
            chunk(1),
            chunk(2),
            n * ps * 4,
            n * 4,
            chunk(0),
            chunk(1),
            chunk(2),
            chunk(0),
            chunk(1),
            chunk(2),
            chunk(0),
            chunk(1),
            chunk(2),
            n * ws * VEC4,
            n * ws * VEC4,
            n * ws * 4,
            n * 4,
            n * ws * VEC4,
            n * INCOMING_CAPACITY as u64 * 4,
            n * 4,
            self.table as u64 * 4,
            self.table as u64 * self.bucket_capacity as u64 * 4,
            blocks * MAX_WALLS as u64 * VEC4,
            FLAG_COUNT as u64 * 4,
            DIAG_SIZE as u64 * 8,
            n * NEIGHBOUR_CAPACITY as u64 * 4,
            n * 4,
            n * VEC4,
            EVENT_LISTS as u64 * n * 4,
            WORK_LISTS as u64 * 4,
            3 * (ARGS_REBUILD as u64 + 1) * 4,
            // moving_walls, wall_table: the walls buffer again (ALIASES), no memory of their own.
            0,
            0,
            n * ps * 4,
            n * ws * VEC4,
            n * ws * VEC4,
            n * 4,
            (ROW_PARTIALS + ROW_SUMS * blocks as usize) as u64 * 8,
            // The profile's and the raster's scratch start empty and grow on demand
            // (engine::rows): their size depends on the walls and on the sample's extent.
            0,
            0,
        ]
    }

    /// Total device memory [B].
    pub fn total_bytes(&self) -> u64 {
        self.binding_bytes().iter().sum()
    }

    /// Device memory per monomer [B] (the table's share included).
    pub fn bytes_per_monomer(&self) -> f64 {
        self.total_bytes() as f64 / self.monomers.max(1) as f64
    }

    /// The largest binding and its name (the first in binding order among equals).
    pub fn largest_binding(&self) -> (&'static str, u64) {
        let bytes = self.binding_bytes();
        let mut largest = 0;
        for (i, b) in bytes.iter().enumerate() {
            if *b > bytes[largest] {
                largest = i;
            }
        }
        (BINDINGS[largest], bytes[largest])
    }

    /// Checks the problem against the device's limits.
    pub fn check(&self, limits: &wgpu::Limits) -> Result<(), SizeError> {
        if self.walls > MAX_WALLS {
            return Err(SizeError::TooManyWalls { walls: self.walls });
        }
        let (name, bytes) = self.largest_binding();
        if bytes > limits.max_storage_buffer_binding_size {
            return Err(SizeError::Binding {
                name,
                bytes,
                limit: limits.max_storage_buffer_binding_size,
                monomers: self.monomers,
            });
        }
        if bytes > limits.max_buffer_size {
            return Err(SizeError::Binding {
                name,
                bytes,
                limit: limits.max_buffer_size,
                monomers: self.monomers,
            });
        }
        if MAX_BINDINGS_PER_PASS > limits.max_storage_buffers_per_shader_stage {
            return Err(SizeError::StorageBuffers {
                needed: MAX_BINDINGS_PER_PASS,
                limit: limits.max_storage_buffers_per_shader_stage,
            });
        }
        let groups = self.monomers.max(self.table).div_ceil(64) as u64;
        if groups > u64::from(limits.max_compute_workgroups_per_dimension) {
            return Err(SizeError::Workgroups {
                groups,
                limit: limits.max_compute_workgroups_per_dimension,
            });
        }
        Ok(())
    }
}

/// A problem the device cannot hold.
#[derive(Clone, Debug, PartialEq)]
pub enum SizeError {
    TooManyWalls {
        walls: usize,
    },
    Binding {
        name: &'static str,
        bytes: u64,
        limit: u64,
        monomers: usize,
    },
    StorageBuffers {
        needed: u32,
        limit: u32,
    },
    Workgroups {
        groups: u64,
        limit: u32,
    },
}

impl fmt::Display for SizeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SizeError::TooManyWalls { walls } => {
                write!(
                    f,
                    "{walls} walls; the GPU engine handles at most {MAX_WALLS}"
                )
            }
            SizeError::Binding {
                name,
                bytes,
                limit,
                monomers,
            } => write!(
                f,
                "{monomers} monomers need {bytes} B in the `{name}` binding, the device allows \
                 {limit} B per storage binding (lower [sample] monomers or [integration] pair_slots; \
                 `dustdem info --monomers N` says what fits)"
            ),
            SizeError::StorageBuffers { needed, limit } => write!(
                f,
                "the GPU engine binds {needed} storage buffers per pass, the device allows {limit}"
            ),
            SizeError::Workgroups { groups, limit } => write!(
                f,
                "{groups} workgroups per dispatch, the device allows {limit}"
            ),
        }
    }
}

impl std::error::Error for SizeError {}

/// One wgpu buffer per binding, plus the staging buffer for the small readback.
#[derive(Debug)]
pub struct Buffers {
    pub sizes: Sizes,
    /// In binding order.
    pub bindings: Vec<wgpu::Buffer>,
    /// Flags then diag, mapped by the host after each batch of steps.
    pub small_readback: wgpu::Buffer,
}

pub const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::COPY_SRC)
    .union(wgpu::BufferUsages::COPY_DST);

impl Buffers {
    /// Zero-filled buffers (at least 64 bytes each: no binding may be empty).
    pub fn new(device: &wgpu::Device, sizes: Sizes) -> Self {
        let mut bindings: Vec<wgpu::Buffer> = Vec::with_capacity(BINDINGS.len());
        for (name, bytes) in BINDINGS.iter().zip(sizes.binding_bytes()) {
            if let Some((_, target)) = ALIASES.iter().find(|(alias, _)| alias == name) {
                let at = BINDINGS.iter().position(|b| b == target).expect("aliased");
                bindings.push(bindings[at].clone());
                continue;
            }
            bindings.push(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(name),
                size: bytes.max(64).next_multiple_of(8),
                // Indirect dispatch arguments, written on the device.
                usage: match *name {
                    "work_args" => STORAGE | wgpu::BufferUsages::INDIRECT,
                    // Bound as `var<uniform>` (kernels::buffer_binding_type).
                    "params" | "walls" => STORAGE | wgpu::BufferUsages::UNIFORM,
                    _ => STORAGE,
                },
                mapped_at_creation: false,
            }));
        }
        let small_readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("small readback"),
            size: Self::small_bytes(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Buffers {
            sizes,
            bindings,
            small_readback,
        }
    }

    pub fn get(&self, name: &str) -> &wgpu::Buffer {
        &self.bindings[Self::index(name)]
    }

    fn index(name: &str) -> usize {
        BINDINGS
            .iter()
            .position(|b| *b == name)
            .unwrap_or_else(|| panic!("no binding `{name}`"))
    }

    /// Replaces the buffer of binding `name` by a zero-filled one of at least `bytes` (a
    /// scratch buffer that has to grow); the bind groups must be built again.
    pub fn grow(&mut self, device: &wgpu::Device, name: &'static str, bytes: u64) {
        self.bindings[Self::index(name)] = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(name),
            size: bytes.max(64).next_multiple_of(8),
            usage: STORAGE,
            mapped_at_creation: false,
        });
    }

    /// Flags (u32, padded to 8 bytes) then the diagnostics block (f64).
    pub fn small_bytes() -> u64 {
        (FLAG_COUNT as u64 * 4).next_multiple_of(8) + DIAG_SIZE as u64 * 8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The limits lavapipe reports (32 storage buffers per stage, 128 MiB per binding).
    fn lavapipe() -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffers_per_shader_stage: 32,
            max_storage_buffer_binding_size: 128 << 20,
            max_buffer_size: 2 << 30,
            ..wgpu::Limits::default()
        }
    }

    #[test]
    fn a_problem_too_large_for_a_binding_names_it_and_what_to_lower() {
        let sizes = Sizes::new(1_000_000, 6, 40, 3);
        let error = sizes.check(&lavapipe()).unwrap_err();
        assert_eq!(sizes.largest_binding().0, "pair_n1_0");
        let text = error.to_string();
        assert!(
            text.contains("1000000 monomers need 426666688 B in the `pair_n1_0` binding")
                && text.contains("134217728 B per storage binding")
                && text.contains("pair_slots"),
            "{text}"
        );
    }

    #[test]
    fn a_million_monomers_fit_lavapipe_with_twelve_pair_slots() {
        // 12 · 10⁶ slots in three chunks of 4 · 10⁶ vectors: 128 000 000 B per binding; the
        // cell table (2²¹ buckets of 16 ids) fills its binding exactly.
        let sizes = Sizes::new(1_000_000, 6, 12, 3);
        assert!(sizes.check(&lavapipe()).is_ok());
        assert_eq!(sizes.slot_chunk(), 4_000_000);
        assert_eq!(sizes.largest_binding(), ("bucket_items", 128 << 20));
        // 2²⁰ monomers is the largest N: one more doubles the cell table.
        assert!(Sizes::new(1 << 20, 6, 12, 3).check(&lavapipe()).is_ok());
        let over = Sizes::new((1 << 20) + 1, 6, 12, 3);
        assert_eq!(over.largest_binding().0, "bucket_items");
        assert!(over.check(&lavapipe()).is_err());
        // More slots than three chunks hold.
        assert!(Sizes::new(1_000_000, 6, 13, 3).check(&lavapipe()).is_err());
    }
}
