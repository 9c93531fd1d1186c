//! The engine's device buffers, one per [`Binding`] of shaders/engine/bindings.wgsl, and what
//! they cost per monomer.
//!
//! Buffers are data only; the pipelines that use them are in `kernels.rs`. Everything is created
//! once for a fixed N and slot counts; nothing is reallocated while the engine runs.

use super::interface::Binding;
use super::layout::{
    GpuParams, GpuWall, ARGS_REBUILD, DIAG_SIZE, EVENT_LISTS, FLAG_COUNT, INCOMING_CAPACITY,
    MAX_WALLS, NEIGHBOUR_CAPACITY, REDUCE_BLOCK, ROW_PARTIALS, ROW_SUMS, SLOT_CHUNKS, TALLY_STRIDE,
    WORK_LISTS,
};
use super::shader::Precision;
use super::transcode::Transcoder;
use std::fmt;

/// Bytes of one vec4<f64>.
const VEC4: u64 = 32;

impl Binding {
    /// The binding whose buffer this one declares a second time, if any. `walls` is declared
    /// three ways (bindings.wgsl): uniform for a wall index the same in every invocation,
    /// read-only storage (`wall_table`) for a wall index that differs between invocations, and
    /// writable storage (`moving_walls`) for the drift, which may not bind it otherwise in the
    /// same dispatch.
    pub fn shares_buffer_of(self) -> Option<Binding> {
        match self {
            Binding::MovingWalls | Binding::WallTable => Some(Binding::Walls),
            _ => None,
        }
    }
}

/// The chunk bindings of the per-slot pointer arrays (see `Sizes::slot_chunk`).
pub const PAIR_N1: [Binding; SLOT_CHUNKS] = [
    Binding::PairN1Chunk0,
    Binding::PairN1Chunk1,
    Binding::PairN1Chunk2,
];
pub const PAIR_N2: [Binding; SLOT_CHUNKS] = [
    Binding::PairN2Chunk0,
    Binding::PairN2Chunk1,
    Binding::PairN2Chunk2,
];

/// The most bindings one pass uses (each pass binds only what its entry point reads or
/// writes; `kernels::tests` derives this from the shaders with naga): `contacts` in the mixed
/// precision, whose split centres take two bindings more than the exact precision's 27.
pub const MAX_BINDINGS_PER_PASS: u32 = 29;

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
    /// Centres held split (voxel, offset, low part: the mixed precision), which the
    /// `position_voxel` and `position_lo` bindings hold; else those are empty.
    pub split_positions: bool,
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
            split_positions: false,
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
    pub fn binding_bytes(&self) -> [u64; Binding::COUNT] {
        Binding::ALL.map(|b| self.bytes(b))
    }

    /// Bytes of binding `b`.
    pub fn bytes(&self, b: Binding) -> u64 {
        let n = self.monomers as u64;
        let ws = self.wall_slots as u64;
        let ps = self.pair_slots as u64;
        let blocks = self.monomers.div_ceil(REDUCE_BLOCK) as u64;
        use Binding::*;
        match b {
            Params => std::mem::size_of::<GpuParams>() as u64,
            // The uniform declaration has room for every wall the diagnostics can hold.
            Walls => MAX_WALLS as u64 * std::mem::size_of::<GpuWall>() as u64,
            Position | Velocity | AngularVelocity | Force | Torque | DampingForce | Aux
            | ReferencePosition => n * VEC4,
            Tally => n * TALLY_STRIDE as u64 * 8,
            PairN1Chunk0 | PairN2Chunk0 | PairResultAChunk0 | PairResultBChunk0
            | PairResultCChunk0 => self.chunk_bytes(0),
            PairN1Chunk1 | PairN2Chunk1 | PairResultAChunk1 | PairResultBChunk1
            | PairResultCChunk1 => self.chunk_bytes(1),
            PairN1Chunk2 | PairN2Chunk2 | PairResultAChunk2 | PairResultBChunk2
            | PairResultCChunk2 => self.chunk_bytes(2),
            PairPartner | ContactList => n * ps * 4,
            PairCount | WallCount | IncomingCount | NeighbourCount | PairTests => n * 4,
            WallN1 | WallAnchor | WallForce | WallDamping | WallTorque => n * ws * VEC4,
            WallId => n * ws * 4,
            Incoming => n * INCOMING_CAPACITY as u64 * 4,
            BucketCount => self.table as u64 * 4,
            BucketItems => self.table as u64 * self.bucket_capacity as u64 * 4,
            Partials => blocks * MAX_WALLS as u64 * VEC4,
            Flags => FLAG_COUNT as u64 * 4,
            Diag => DIAG_SIZE as u64 * 8,
            NeighbourList => n * NEIGHBOUR_CAPACITY as u64 * 4,
            WorkList => EVENT_LISTS as u64 * n * 4,
            Work => WORK_LISTS as u64 * 4,
            WorkArgs => 3 * (ARGS_REBUILD as u64 + 1) * 4,
            // The walls buffer again (shares_buffer_of), no memory of their own.
            MovingWalls | WallTable => 0,
            RowData => (ROW_PARTIALS + ROW_SUMS * blocks as usize) as u64 * 8,
            // The profile's and the raster's scratch start empty and grow on demand
            // (engine::rows): their size depends on the walls and on the sample's extent.
            RowProfileData | RowBits => 0,
            PositionVoxel if self.split_positions => n * 16,
            PositionLo if self.split_positions => n * VEC4,
            PositionVoxel | PositionLo => 0,
        }
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
        (Binding::ALL[largest].name(), bytes[largest])
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
    /// Zero-filled buffers (at least 64 bytes each: no binding may be empty), in the device
    /// layout of `precision` (`transcode`: the mixed one holds f32 where the exact holds f64).
    pub fn new(device: &wgpu::Device, sizes: Sizes, precision: Precision) -> Self {
        let device_bytes = |b: Binding| match precision {
            Precision::Exact => sizes.bytes(b),
            Precision::Mixed => Transcoder::engine().element(b).mixed_bytes(sizes.bytes(b)),
        };
        let mut bindings: Vec<wgpu::Buffer> = Vec::with_capacity(Binding::COUNT);
        for binding in Binding::ALL {
            if let Some(target) = binding.shares_buffer_of() {
                bindings.push(bindings[target as usize].clone());
                continue;
            }
            bindings.push(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(binding.name()),
                size: device_bytes(binding).max(64).next_multiple_of(8),
                usage: match binding {
                    // Indirect dispatch arguments, written on the device.
                    Binding::WorkArgs => STORAGE | wgpu::BufferUsages::INDIRECT,
                    // Bound as `var<uniform>` (kernels::buffer_binding_type).
                    Binding::Params | Binding::Walls => STORAGE | wgpu::BufferUsages::UNIFORM,
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

    /// Bytes of all buffers as allocated (a buffer declared under several bindings once).
    pub fn device_bytes(&self) -> u64 {
        Binding::ALL
            .iter()
            .filter(|b| b.shares_buffer_of().is_none())
            .map(|&b| self.get(b).size())
            .sum()
    }

    pub fn get(&self, binding: Binding) -> &wgpu::Buffer {
        &self.bindings[binding as usize]
    }

    /// Replaces the buffer of `binding` by a zero-filled one of at least `bytes` (a scratch
    /// buffer that has to grow); the bind groups must be built again.
    pub fn grow(&mut self, device: &wgpu::Device, binding: Binding, bytes: u64) {
        self.bindings[binding as usize] = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(binding.name()),
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
