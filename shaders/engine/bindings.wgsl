// requires: pointers accumulators
//
// The engine's device state: one bind group shared by every pass, so the step script binds it
// once and every pipeline has the same explicit layout (SPIR-V passthrough modules cannot be
// reflected). Mirrored by src/backend/gpu/buffers.rs (binding numbers) and src/backend/gpu/layout.rs (structs);
// a test reads these structs with naga and checks sizes and offsets against the Rust side.
//
// Vectors are vec4<f64> (32 bytes, the w component unused unless named), so every array element
// is naturally aligned and a vector is one load.

// Contact constants of one contact kind (material::ContactConstants, same order).
struct Constants {
    reduced_radius: f64,
    a0: f64,
    delta0: f64,
    f_c: f64,
    delta_c: f64,
    k_r: f64,
    k_s: f64,
    k_t: f64,
    xi_crit: f64,
    zeta_crit: f64,
    phi_crit: f64,
    _pad: f64,
}

struct Params {
    // Monomers, walls, slots per monomer.
    n: u32,
    wall_count: u32,
    pair_slots: u32,
    wall_slots: u32,
    // Hash table of cells: size − 1 (a power of two), ids per bucket.
    table_mask: u32,
    bucket_capacity: u32,
    // Damping::kind of model/damping.wgsl.
    damping_kind: u32,
    // Elements in each binding of a per-slot vector array (see load_pair_n1).
    slot_chunk: u32,
    // Most workgroups a pass over a work list is dispatched with (see push_work).
    work_groups_max: u32,
    _pad: u32,
    // Keeps `pair` 16-byte aligned, as a uniform buffer requires.
    _pad2: u32,
    _pad3: u32,
    dt: f64,
    radius: f64,
    inverse_mass: f64,
    inverse_inertia: f64,
    // Edge of a binning cell and cutoff of the candidate lists [cm]: 2r + skin.
    cell: f64,
    e_star: f64,
    poisson: f64,
    damping_value: f64,
    pair: Constants,
    // The mixed precision's double-f32 radius and (2r)² (what their f32 leave out in the _lo
    // parts): overlaps to 10⁻⁵ δ₀ need more than an f32 radius (shaders/mixed_engine/
    // positions.wgsl). Unread in the exact precision.
    radius_lo: f64,
    two_r_squared: f64,
    two_r_squared_lo: f64,
}

// A planar wall; `normal` points into the domain. The point moves with `velocity`.
struct Wall {
    point: vec4<f64>,
    normal: vec4<f64>,
    velocity: vec4<f64>,
    k: Constants,
    // The mixed precision's low part of `point` (a double-f32); zero and unread in the exact.
    point_lo: vec4<f64>,
}

// Per monomer: the scales of its inverse mass and inertia (0 for a fixed monomer, as
// state::Monomers has them), and the power Σ_w F_w·v_w dt of its wall contacts and of their
// damping part at the current step (trapezoid bookkeeping of the wall work).
struct MonomerAux {
    inverse_mass_scale: f64,
    inverse_inertia_scale: f64,
    wall_power: f64,
    damping_power: f64,
}

// The per-slot pointer records (`ContactPointer`: a contact's pointer on its owner and its
// twisting angle, state::PairContact's n1 and twist, state::WallContact's; `SecondPointer`: n2)
// are in engine/pointers.wgsl, one file per precision.

// Walls the diagnostics block has room for.
const MAX_WALLS: u32 = 8u;
// Pair contacts a monomer can take from owners of lower index (equal spheres touch at most 12).
const INCOMING_CAPACITY: u32 = 16u;
// Monomers one invocation of reduce_walls sums, in index order.
const REDUCE_BLOCK: u32 = 64u;
// Invocations of reduce_diagnostics (one workgroup): strided partial sums, added in order.
const DIAG_THREADS: u32 = 64u;
// Bindings each per-slot vector array is split into (see load_pair_n1).
const SLOT_CHUNKS: u32 = 3u;
// Chunks in use: 1 where every per-slot array fits its first binding. The engine's pipelines
// set it to the value their problem needs (backend::gpu::shader::Assembled::with_one_slot_chunk),
// so the chunk selection below folds away where there is one chunk.
override SLOT_CHUNKS_IN_USE: u32 = 3u;
// Candidate partners j > i one monomer's list holds (within 2r + skin: about 12 at φ = 0.74).
const NEIGHBOUR_CAPACITY: u32 = 24u;

// Work lists (see `work_list`), and the workgroup size of the passes dispatched over a list
// (one SIMD group of lavapipe).
// The owners with contact events, inelastic corrections or wall contacts this step (the
// contacts pass): the owner's index, with OWNER_EVENTS, OWNER_CORRECTIONS, OWNER_WALLS set
// for what it has.
const WORK_CONTACTS: u32 = 0u;
// The pair contacts (slot indices), for the passes that run one invocation per contact.
const WORK_PAIRS: u32 = 1u;
const WORK_LISTS: u32 = 2u;
// The dispatch arguments after the lists' (work_args): the two neighbour passes, of n/64 groups
// when integrate_drift asks for a rebuild and of none otherwise (a pass that returns at once
// still costs lavapipe a full dispatch).
const ARGS_REBUILD: u32 = 2u;
// The lists of owners (in `work_list`); contacts_scan fills every list, integrate_drift
// empties them.
const EVENT_LISTS: u32 = 1u;
// What an owner in WORK_CONTACTS has to do, in bits above any monomer index (N < 2^29: the
// buffers' limits keep N far lower, see backend::gpu::buffers::Sizes::check).
const OWNER_EVENTS: u32 = 0x80000000u;
const OWNER_CORRECTIONS: u32 = 0x40000000u;
const OWNER_WALLS: u32 = 0x20000000u;
const OWNER_INDEX: u32 = 0x1fffffffu;
const WORK_GROUP: u32 = 8u;
// Workgroup size of the passes over the pair-contact list.
const PAIR_GROUP: u32 = 64u;
// Workgroup size of the passes with one invocation per monomer (backend::gpu::engine dispatches
// ⌈n / MONOMER_GROUP⌉ groups; integrate_drift sizes the neighbour passes alike).
const MONOMER_GROUP: u32 = 64u;

// Bits of `pair_tests`: a contact of the owner will break at the coming contact events (δ <
// −δ_c); a contact is beyond an inelastic limit.
const PAIR_TEST_BREAKS: u32 = 1u;
const PAIR_TEST_BEYOND: u32 = 2u;

// Overflow and failure flags: the lowest monomer index concerned, or NO_MONOMER.
const NO_MONOMER: u32 = 0xffffffffu;
const FLAG_PAIR_SLOTS: u32 = 0u;
const FLAG_WALL_SLOTS: u32 = 1u;
const FLAG_BUCKET: u32 = 2u;
const FLAG_INCOMING: u32 = 3u;
const FLAG_NON_FINITE: u32 = 4u;
const FLAG_NEIGHBOURS: u32 = 5u;
// Not an error: some monomer moved half the skin since the candidate lists were built (the
// lowest such index); the neighbour passes rebuild them and the contacts pass lowers it.
const FLAG_REBUILD: u32 = 6u;
// Length of `flags` (room for one more flag); the host reads all of them back.
const FLAG_COUNT: u32 = 8u;

// Per-monomer cumulative energy channels (state::Dissipation, then the wall work).
const TALLY_STRIDE: u32 = 8u;
const TALLY_BREAKING: u32 = 0u;
const TALLY_FORMING: u32 = 1u;
const TALLY_DAMPING: u32 = 2u;
const TALLY_ROLLING: u32 = 3u;
const TALLY_SLIDING: u32 = 4u;
const TALLY_TWISTING: u32 = 5u;
const TALLY_WALLS: u32 = 6u;
const TALLY_WALL_WORK: u32 = 7u;

// The diagnostics block (f64): tally sums, contact counts, wall forces now and summed.
const DIAG_TALLY: u32 = 0u;
const DIAG_PAIR_CONTACTS: u32 = 8u;
const DIAG_WALL_CONTACTS: u32 = 9u;
const DIAG_STEPS: u32 = 10u;
const DIAG_WALL_FORCE: u32 = 16u;
const DIAG_WALL_FORCE_SUM: u32 = 48u;
const DIAG_SIZE: u32 = 80u;
// The row measures (passes/rows.wgsl) in `row_data` (f64): what the host writes before the
// row kernels run, then their results, then the per-block partial sums.
const ROW_MASS: u32 = 0u;
const ROW_INERTIA: u32 = 1u;
// 4/3 π r³, slabs of a profile (bottom, thickness, count), the raster of the projected area
// (x0, y0, pixel edge, pixels in x and y); counts as f64.
const ROW_SPHERE: u32 = 2u;
const ROW_SLAB_BOTTOM: u32 = 3u;
const ROW_SLAB_THICKNESS: u32 = 4u;
const ROW_SLABS: u32 = 5u;
const ROW_X0: u32 = 6u;
const ROW_Y0: u32 = 7u;
const ROW_PIXEL: u32 = 8u;
const ROW_NX: u32 = 9u;
const ROW_NY: u32 = 10u;
// Results of row_sums_final: kinetic, rotational, normal, tangential energy; least x, y and
// greatest x, y of the centres (ROW_SUMS numbers, as per block from ROW_PARTIALS on).
const ROW_RESULTS: u32 = 16u;
const ROW_SUMS: u32 = 8u;
const ROW_PARTIALS: u32 = 24u;

@group(0) @binding(0) var<uniform> params: Params;
// The walls, declared three ways over one buffer (backend::gpu::buffers::ALIASES). Indexed by a wall
// number every invocation shares (a loop over the walls): `walls`, a uniform, which llvmpipe
// loads once per SIMD group where it loads storage lane by lane. Indexed by a wall number of
// the invocation's own (a wall contact's `wall_id`): `wall_table`, read-only storage, as a
// uniform read at a per-lane index was slower still. integrate_drift moves the walls through
// `moving_walls`, writable storage.
@group(0) @binding(1) var<uniform> walls: array<Wall, MAX_WALLS>;
@group(0) @binding(2) var<storage, read_write> position: array<vec4<f64>>;
@group(0) @binding(3) var<storage, read_write> velocity: array<vec4<f64>>;
@group(0) @binding(4) var<storage, read_write> angular_velocity: array<vec4<f64>>;
@group(0) @binding(5) var<storage, read_write> force: array<vec4<f64>>;
@group(0) @binding(6) var<storage, read_write> torque: array<vec4<f64>>;
@group(0) @binding(7) var<storage, read_write> damping_force: array<vec4<f64>>;
@group(0) @binding(8) var<storage, read_write> aux: array<MonomerAux>;
@group(0) @binding(9) var<storage, read_write> tally: array<TallyEntry>;
// Pair slots, `pair_slots` per owner (slot index owner · pair_slots + slot): pointer of the
// owner (w: twist integral), pointer of the partner, partner index; the count per owner.
// Per-slot vectors are split into SLOT_CHUNKS bindings of params.slot_chunk elements, so that
// no binding outgrows the device's limit (lavapipe: 128 MiB, 4.2 million vectors); only the
// load_/store_ functions below index them.
@group(0) @binding(10) var<storage, read_write> pair_n1_0: array<ContactPointer>;
@group(0) @binding(11) var<storage, read_write> pair_n1_1: array<ContactPointer>;
@group(0) @binding(12) var<storage, read_write> pair_n1_2: array<ContactPointer>;
@group(0) @binding(13) var<storage, read_write> pair_n2_0: array<SecondPointer>;
@group(0) @binding(14) var<storage, read_write> pair_n2_1: array<SecondPointer>;
@group(0) @binding(15) var<storage, read_write> pair_n2_2: array<SecondPointer>;
@group(0) @binding(16) var<storage, read_write> pair_partner: array<u32>;
@group(0) @binding(17) var<storage, read_write> pair_count: array<u32>;
// Per-contact results of the forces pass (force on the owner f, its damping part fd, torque
// on the owner m1, torque on the partner m2: twelve numbers) packed into three vectors per
// slot: a = (f, fd.x), b = (fd.yz, m1.xy), c = (m1.z, m2).
@group(0) @binding(18) var<storage, read_write> pair_result_a_0: array<vec4<f64>>;
@group(0) @binding(19) var<storage, read_write> pair_result_a_1: array<vec4<f64>>;
@group(0) @binding(20) var<storage, read_write> pair_result_a_2: array<vec4<f64>>;
@group(0) @binding(21) var<storage, read_write> pair_result_b_0: array<vec4<f64>>;
@group(0) @binding(22) var<storage, read_write> pair_result_b_1: array<vec4<f64>>;
@group(0) @binding(23) var<storage, read_write> pair_result_b_2: array<vec4<f64>>;
@group(0) @binding(24) var<storage, read_write> pair_result_c_0: array<vec4<f64>>;
@group(0) @binding(25) var<storage, read_write> pair_result_c_1: array<vec4<f64>>;
@group(0) @binding(26) var<storage, read_write> pair_result_c_2: array<vec4<f64>>;
// Wall slots, `wall_slots` per monomer: pointer (w: twist), anchor, wall index; the count.
@group(0) @binding(27) var<storage, read_write> wall_n1: array<ContactPointer>;
@group(0) @binding(28) var<storage, read_write> wall_anchor: array<WallAnchor>;
@group(0) @binding(29) var<storage, read_write> wall_id: array<u32>;
@group(0) @binding(30) var<storage, read_write> wall_count: array<u32>;
// Force of each wall contact on its monomer (for the per-wall reduction and the gather), its
// damping part and the torque on the monomer, as wall_contacts_of (contacts pass) found them.
@group(0) @binding(31) var<storage, read_write> wall_force: array<vec4<f64>>;
// Pair slots (owner · pair_slots + slot) whose partner is this monomer, INCOMING_CAPACITY per
// monomer, in arrival order; sorted before they are summed.
@group(0) @binding(32) var<storage, read_write> incoming: array<u32>;
@group(0) @binding(33) var<storage, read_write> incoming_count: array<atomic<u32>>;
// Cell hash table: ids per bucket and their count.
@group(0) @binding(34) var<storage, read_write> bucket_count: array<atomic<u32>>;
@group(0) @binding(35) var<storage, read_write> bucket_items: array<u32>;
// Per-block partial wall forces, MAX_WALLS per block of REDUCE_BLOCK monomers.
@group(0) @binding(36) var<storage, read_write> partials: array<vec4<f64>>;
@group(0) @binding(37) var<storage, read_write> flags: array<atomic<u32>>;
@group(0) @binding(38) var<storage, read_write> diag: array<f64>;
// Candidate lists (Verlet lists): the monomers j > i within 2r + skin that are not partners of
// i, ascending, NEIGHBOUR_CAPACITY per monomer; their lengths; positions when they were built.
// A contact that forms takes its partner out of the list and one that breaks puts it back
// (contacts pass), so partners and candidates together are every j > i within 2r + skin at the
// last build; the scan then tests for new contacts only the monomers that can form one.
@group(0) @binding(39) var<storage, read_write> neighbour_list: array<u32>;
@group(0) @binding(40) var<storage, read_write> neighbour_count: array<u32>;
@group(0) @binding(41) var<storage, read_write> reference_position: array<vec4<f64>>;
// Work lists: the owners with contact events, inelastic corrections or wall contacts this step
// (contacts pass), found by the scan; n entries per list, in no fixed order
// (each owner's work touches only its own slots and tally, so the order cannot change a
// result). lavapipe runs every branch of a kernel for every invocation, masked, so rare and
// expensive work inside a per-monomer kernel costs as if every monomer did it; dispatched
// indirectly over its list, it costs what it does.
@group(0) @binding(42) var<storage, read_write> work_list: array<u32>;
// Length of each list (at WORK_CONTACTS, WORK_PAIRS).
@group(0) @binding(43) var<storage, read_write> work: array<atomic<u32>>;
// Indirect dispatch arguments (workgroups x, y, z) of the pass that processes each list, three
// words per list. A separate buffer: a dispatch may not bind as storage the buffer its
// arguments come from.
@group(0) @binding(44) var<storage, read_write> work_args: array<atomic<u32>>;
// The buffer of `walls`, writable, for integrate_drift only, and read-only for a per-invocation
// wall index (see `walls`).
@group(0) @binding(45) var<storage, read_write> moving_walls: array<Wall>;
@group(0) @binding(46) var<storage, read> wall_table: array<Wall>;
// Every pair contact's slot index (owner · pair_slots + slot), its length in work[WORK_PAIRS]:
// the contact-parallel passes (integrate_pairs, forces) run one invocation per entry. Built
// for each step's contact events by contacts_scan, in no fixed order (each contact's work
// touches only its own slot). An owner's loop over its slots keeps most of lavapipe's SIMD
// lanes idle (an owner has about one contact, the group runs as many rounds as its busiest
// lane); a list of contacts keeps them all busy.
@group(0) @binding(47) var<storage, read_write> contact_list: array<u32>;
@group(0) @binding(48) var<storage, read_write> wall_damping: array<vec4<f64>>;
@group(0) @binding(49) var<storage, read_write> wall_torque: array<vec4<f64>>;
// What the contact-parallel tests found for each owner's pair contacts, as PAIR_TEST_* bits:
// cleared by integrate_kick, set by integrate_pairs (or contacts_pair_tests), read by
// contacts_scan.
@group(0) @binding(50) var<storage, read_write> pair_tests: array<atomic<u32>>;
// The row measures (passes/rows.wgsl): parameters, results and block sums (ROW_*); the solid
// volume per slab (row_profile[k]) and per (slab, block) after them (at ROW_SLABS + k · blocks
// + b); the count of covered pixels (row_bits[0]) and the coverage bitmap after it. The last
// two grow with the profile and the raster (backend::gpu::engine::rows).
@group(0) @binding(51) var<storage, read_write> row_data: array<f64>;
@group(0) @binding(52) var<storage, read_write> row_profile_data: array<f64>;
@group(0) @binding(53) var<storage, read_write> row_bits: array<atomic<u32>>;
// The mixed precision's split centres (shaders/mixed_engine/positions.wgsl): the voxel and the
// low part of the offset, which `position` then holds. Unread in the exact precision.
@group(0) @binding(54) var<storage, read_write> position_voxel: array<vec4<i32>>;
@group(0) @binding(55) var<storage, read_write> position_lo: array<vec4<f64>>;

// Which binding of a per-slot array holds slot index `idx`, and where: (chunk, element).
fn slot_chunk_of(idx: u32) -> vec2<u32> {
    if SLOT_CHUNKS_IN_USE == 1u {
        return vec2<u32>(0u, idx);
    }
    let c = min(idx / params.slot_chunk, SLOT_CHUNKS - 1u);
    return vec2<u32>(c, idx - c * params.slot_chunk);
}

fn load_pair_n1(idx: u32) -> ContactPointer {
    let at = slot_chunk_of(idx);
    if at.x == 0u {
        return pair_n1_0[at.y];
    }
    if at.x == 1u {
        return pair_n1_1[at.y];
    }
    return pair_n1_2[at.y];
}

fn store_pair_n1(idx: u32, value: ContactPointer) {
    let at = slot_chunk_of(idx);
    if at.x == 0u {
        pair_n1_0[at.y] = value;
    } else if at.x == 1u {
        pair_n1_1[at.y] = value;
    } else {
        pair_n1_2[at.y] = value;
    }
}

fn load_pair_n2(idx: u32) -> SecondPointer {
    let at = slot_chunk_of(idx);
    if at.x == 0u {
        return pair_n2_0[at.y];
    }
    if at.x == 1u {
        return pair_n2_1[at.y];
    }
    return pair_n2_2[at.y];
}

fn store_pair_n2(idx: u32, value: SecondPointer) {
    let at = slot_chunk_of(idx);
    if at.x == 0u {
        pair_n2_0[at.y] = value;
    } else if at.x == 1u {
        pair_n2_1[at.y] = value;
    } else {
        pair_n2_2[at.y] = value;
    }
}

// What the forces pass found for one pair contact (all on the owner's side but m2).
struct PairResult {
    f: vec3<f64>,
    fd: vec3<f64>,
    m1: vec3<f64>,
    m2: vec3<f64>,
}

fn store_pair_result(idx: u32, r: PairResult) {
    let a = vec4<f64>(r.f, r.fd.x);
    let b = vec4<f64>(r.fd.yz, r.m1.xy);
    let c = vec4<f64>(r.m1.z, r.m2);
    let at = slot_chunk_of(idx);
    if at.x == 0u {
        pair_result_a_0[at.y] = a;
        pair_result_b_0[at.y] = b;
        pair_result_c_0[at.y] = c;
    } else if at.x == 1u {
        pair_result_a_1[at.y] = a;
        pair_result_b_1[at.y] = b;
        pair_result_c_1[at.y] = c;
    } else {
        pair_result_a_2[at.y] = a;
        pair_result_b_2[at.y] = b;
        pair_result_c_2[at.y] = c;
    }
}

fn load_pair_result(idx: u32) -> PairResult {
    let at = slot_chunk_of(idx);
    var a: vec4<f64>;
    var b: vec4<f64>;
    var c: vec4<f64>;
    if at.x == 0u {
        a = pair_result_a_0[at.y];
        b = pair_result_b_0[at.y];
        c = pair_result_c_0[at.y];
    } else if at.x == 1u {
        a = pair_result_a_1[at.y];
        b = pair_result_b_1[at.y];
        c = pair_result_c_1[at.y];
    } else {
        a = pair_result_a_2[at.y];
        b = pair_result_b_2[at.y];
        c = pair_result_c_2[at.y];
    }
    return PairResult(a.xyz, vec3<f64>(a.w, b.x, b.y), vec3<f64>(b.zw, c.x), c.yzw);
}

fn add_tally(i: u32, channel: u32, value: f64) {
    let at = i * TALLY_STRIDE + channel;
    tally[at] = accumulate(tally[at], value);
}

fn flag(which: u32, monomer: u32) {
    atomicMin(&flags[which], monomer);
}

// Appends monomer `i` to work list `list` and widens the list's indirect dispatch to cover it,
// up to params.work_groups_max workgroups (a dispatch may have no more per dimension; a longer
// list is walked with a stride, see work_item).
fn push_work(list: u32, i: u32) {
    let k = atomicAdd(&work[list], 1u);
    work_list[list * params.n + k] = i;
    // Only the entry that opens a workgroup widens the dispatch (fewer atomics on one word).
    if k % WORK_GROUP == 0u {
        atomicMax(&work_args[3u * list], min(k / WORK_GROUP + 1u, params.work_groups_max));
    }
}

// Appends the `count` slots of owner `i` to the pair-contact list and widens the list's
// indirect dispatch to cover them (up to params.work_groups_max groups; longer lists are walked
// with a stride).
fn push_pairs(i: u32, count: u32) {
    let at = atomicAdd(&work[WORK_PAIRS], count);
    for (var slot = 0u; slot < count; slot++) {
        contact_list[at + slot] = i * params.pair_slots + slot;
    }
    // Only a push that reaches into a new workgroup widens the dispatch (fewer atomics on one
    // word): the push holding a group's first entry always does.
    let groups = (at + count + PAIR_GROUP - 1u) / PAIR_GROUP;
    if groups > (at + PAIR_GROUP - 1u) / PAIR_GROUP {
        atomicMax(&work_args[3u * WORK_PAIRS], min(groups, params.work_groups_max));
    }
}

// Whether pair-contact list entry `idx` (a slot index) holds a contact now: the list may hold
// slots that the contact events emptied.
fn pair_slot_in_use(idx: u32) -> bool {
    let i = idx / params.pair_slots;
    return idx - i * params.pair_slots < pair_count[i];
}

// Whether j is among the first `count` partners of owner i.
fn has_pair(i: u32, count: u32, j: u32) -> bool {
    for (var slot = 0u; slot < count; slot++) {
        if pair_partner[i * params.pair_slots + slot] == j {
            return true;
        }
    }
    return false;
}

// Adds j to owner i's candidate list, in ascending order (a contact of i with j broke).
fn insert_candidate(i: u32, j: u32) {
    let base = i * NEIGHBOUR_CAPACITY;
    let count = neighbour_count[i];
    if count >= NEIGHBOUR_CAPACITY {
        flag(FLAG_NEIGHBOURS, i);
        return;
    }
    var at = count;
    while at > 0u && neighbour_list[base + at - 1u] > j {
        neighbour_list[base + at] = neighbour_list[base + at - 1u];
        at -= 1u;
    }
    neighbour_list[base + at] = j;
    neighbour_count[i] = count + 1u;
}

// Length of work list `list`.
fn work_length(list: u32) -> u32 {
    return atomicLoad(&work[list]);
}

// Entry `k` of work list `list`.
fn work_item(list: u32, k: u32) -> u32 {
    return work_list[list * params.n + k];
}
