//! The host's bytes and the device's in the mixed precision.
//!
//! The host writes and reads every buffer in the layout the f64 text of
//! shaders/engine/bindings.wgsl gives it (the `bytemuck` structs of `layout.rs`, `[f64; 4]`
//! vectors, f64 arrays). In the mixed precision the device holds the f32 text's layout of the
//! same declarations: each f64 becomes an f32, and offsets, strides and struct sizes shrink by
//! WGSL's alignment rules. Both layouts are read from naga (one source: the two texts of the
//! same file), so nothing here repeats a declaration; a binding added to the WGSL is transcoded
//! without a change here. Scalars are paired by their path (member names, component indices);
//! a member `<m>_lo` of the f32 text that the f64 text lacks holds the low part of `<m>`
//! (a double-f32: `shaders/mixed_engine/pointers.wgsl`).

use super::interface::Binding;
use super::shader::{bindings_module, Precision};
use naga::proc::Layouter;
use naga::{ArraySize, Handle, Module, Scalar, ScalarKind, Type, TypeInner};
use std::sync::OnceLock;

/// One scalar of an element: where it lies in each layout and whether it changes width.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Leaf {
    exact: u32,
    mixed: u32,
    /// An f64 of the exact layout, an f32 of the mixed one; otherwise four bytes copied.
    narrowed: bool,
    /// Where the mixed layout keeps what the f32 leaves out of the f64, if it does.
    mixed_lo: Option<u32>,
}

/// The repeating unit of one binding (an array's element, or the whole variable) in both
/// layouts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ElementLayout {
    pub exact_stride: u64,
    pub mixed_stride: u64,
    leaves: Vec<Leaf>,
}

impl ElementLayout {
    /// Device bytes in the mixed precision of `exact_bytes` host bytes (whole elements; a
    /// partial last element counts whole).
    pub fn mixed_bytes(&self, exact_bytes: u64) -> u64 {
        exact_bytes.div_ceil(self.exact_stride) * self.mixed_stride
    }

    /// The device offset of the element at host offset `exact_offset` (an element boundary).
    pub fn mixed_offset(&self, exact_offset: u64) -> u64 {
        assert_eq!(
            exact_offset % self.exact_stride,
            0,
            "offset {exact_offset} is inside an element of {} B",
            self.exact_stride
        );
        exact_offset / self.exact_stride * self.mixed_stride
    }

    /// Host bytes (whole elements) in the device's mixed layout. An f64 beyond f32's range
    /// becomes f32's largest finite value of its sign, as the shaders' sentinels do
    /// (`shader::precision`); padding is zero.
    pub fn encode(&self, exact: &[u8]) -> Vec<u8> {
        let elements = self.whole_elements(exact.len(), self.exact_stride);
        let mut out = vec![0u8; elements * self.mixed_stride as usize];
        for e in 0..elements {
            let (from, to) = (
                e * self.exact_stride as usize,
                e * self.mixed_stride as usize,
            );
            for leaf in &self.leaves {
                let (x, m) = (from + leaf.exact as usize, to + leaf.mixed as usize);
                if leaf.narrowed {
                    let value = f64::from_le_bytes(exact[x..x + 8].try_into().unwrap());
                    let hi = narrow(value);
                    out[m..m + 4].copy_from_slice(&hi.to_le_bytes());
                    if let Some(lo_at) = leaf.mixed_lo {
                        let lo = (value - f64::from(hi)) as f32;
                        let l = to + lo_at as usize;
                        out[l..l + 4].copy_from_slice(&lo.to_le_bytes());
                    }
                } else {
                    out[m..m + 4].copy_from_slice(&exact[x..x + 4]);
                }
            }
        }
        out
    }

    /// Device bytes (whole elements) of the mixed layout in the host's layout.
    pub fn decode(&self, mixed: &[u8]) -> Vec<u8> {
        let elements = self.whole_elements(mixed.len(), self.mixed_stride);
        let mut out = vec![0u8; elements * self.exact_stride as usize];
        for e in 0..elements {
            let (from, to) = (
                e * self.mixed_stride as usize,
                e * self.exact_stride as usize,
            );
            for leaf in &self.leaves {
                let (m, x) = (from + leaf.mixed as usize, to + leaf.exact as usize);
                if leaf.narrowed {
                    let f32_at =
                        |at: usize| f32::from_le_bytes(mixed[at..at + 4].try_into().unwrap());
                    let lo = leaf
                        .mixed_lo
                        .map_or(0.0, |l| f64::from(f32_at(from + l as usize)));
                    let value = f64::from(f32_at(m)) + lo;
                    out[x..x + 8].copy_from_slice(&value.to_le_bytes());
                } else {
                    out[x..x + 4].copy_from_slice(&mixed[m..m + 4]);
                }
            }
        }
        out
    }

    fn whole_elements(&self, bytes: usize, stride: u64) -> usize {
        assert_eq!(
            bytes as u64 % stride,
            0,
            "{bytes} B is not a whole number of {stride}-byte elements"
        );
        bytes / stride as usize
    }
}

/// f64 to the nearest f32, out-of-range finite values to f32's largest of the same sign.
fn narrow(value: f64) -> f32 {
    if value.is_finite() {
        value.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    } else {
        value as f32
    }
}

/// Every binding's [`ElementLayout`], in binding order.
#[derive(Debug)]
pub struct Transcoder {
    elements: Vec<ElementLayout>,
}

impl Transcoder {
    /// The layouts of the engine's bindings (read from naga once per process). The texts are
    /// built in and every pass that includes them has been validated before an engine asks
    /// (`Kernels::new`), so a failure here is a defect of the build, not of the input.
    pub fn engine() -> &'static Transcoder {
        static ENGINE: OnceLock<Transcoder> = OnceLock::new();
        ENGINE.get_or_init(|| {
            let module = |p: Precision| {
                bindings_module(p).unwrap_or_else(|e| panic!("bindings.wgsl, {}: {e}", p.name()))
            };
            Transcoder::from_modules(&module(Precision::Exact), &module(Precision::Mixed))
        })
    }

    /// The layouts of the bindings `exact` declares, paired with the same bindings of `mixed`.
    pub fn from_modules(exact: &Module, mixed: &Module) -> Transcoder {
        let (exact_layouts, mixed_layouts) = (layouter(exact), layouter(mixed));
        let elements = Binding::ALL
            .iter()
            .map(|&b| {
                let (exact_stride, x) = element_leaves(exact, &exact_layouts, b);
                let (mixed_stride, m) = element_leaves(mixed, &mixed_layouts, b);
                ElementLayout {
                    exact_stride,
                    mixed_stride,
                    leaves: paired(b, &x, &m),
                }
            })
            .collect();
        Transcoder { elements }
    }

    pub fn element(&self, binding: Binding) -> &ElementLayout {
        &self.elements[binding as usize]
    }
}

fn layouter(module: &Module) -> Layouter {
    let mut layouter = Layouter::default();
    layouter
        .update(module.to_ctx())
        .expect("a validated module has a layout");
    layouter
}

/// A scalar of one layout: its path (member names and component indices), offset, and whether
/// it is an f64.
type ScalarAt = (String, u32, bool);

/// The exact layout's scalars paired with the mixed layout's by path; every scalar of both
/// must find its place.
fn paired(b: Binding, exact: &[ScalarAt], mixed: &[ScalarAt]) -> Vec<Leaf> {
    let find = |path: &str| mixed.iter().find(|(p, _, _)| p == path);
    let low_part_path = |path: &str| match path.split_once('/') {
        Some((member, rest)) => format!("{member}_lo/{rest}"),
        None => format!("{path}_lo"),
    };
    let leaves: Vec<Leaf> = exact
        .iter()
        .map(|(path, at, wide)| {
            let (_, mixed_at, mixed_wide) = find(path)
                .unwrap_or_else(|| panic!("`{}`: {path} is not in the f32 text", b.name()));
            assert!(!mixed_wide, "`{}`: an f64 in the f32 text", b.name());
            // A low part the f64 text declares too is a member of its own.
            let lo_path = low_part_path(path);
            let own = exact.iter().any(|(p, _, _)| *p == lo_path);
            let lo = find(&lo_path).filter(|_| *wide && !own).map(|(_, l, _)| *l);
            Leaf {
                exact: *at,
                mixed: *mixed_at,
                narrowed: *wide,
                mixed_lo: lo,
            }
        })
        .collect();
    let placed = leaves.len() + leaves.iter().filter(|l| l.mixed_lo.is_some()).count();
    assert_eq!(
        placed,
        mixed.len(),
        "`{}`: f32 scalars without an f64 counterpart",
        b.name()
    );
    leaves
}

/// The stride of binding `b`'s element and its scalars.
fn element_leaves(module: &Module, layouts: &Layouter, b: Binding) -> (u64, Vec<ScalarAt>) {
    let variable = module
        .global_variables
        .iter()
        .map(|(_, v)| v)
        .find(|v| v.binding.as_ref().map(|r| r.binding) == Some(b as u32))
        .unwrap_or_else(|| panic!("`{}` is not declared", b.name()));
    let (element, stride) = match module.types[variable.ty].inner {
        TypeInner::Array { base, stride, .. } => (base, stride),
        _ => (variable.ty, layouts[variable.ty].size),
    };
    let mut leaves = Vec::new();
    scalars(module, element, "", 0, &mut leaves);
    (u64::from(stride), leaves)
}

/// Every scalar of type `ty` at `base`, in declaration order, its path under `path`.
fn scalars(module: &Module, ty: Handle<Type>, path: &str, base: u32, out: &mut Vec<ScalarAt>) {
    let wide = |s: Scalar| {
        assert!(s.width == 4 || (s.kind == ScalarKind::Float && s.width == 8));
        s.width == 8
    };
    let under = |name: &str| {
        if path.is_empty() {
            name.to_string()
        } else {
            format!("{path}/{name}")
        }
    };
    match &module.types[ty].inner {
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => out.push((path.to_string(), base, wide(*s))),
        TypeInner::Vector { size, scalar } => {
            for k in 0..*size as u32 {
                let at = base + k * u32::from(scalar.width);
                out.push((under(&k.to_string()), at, wide(*scalar)));
            }
        }
        TypeInner::Struct { members, .. } => {
            for m in members {
                let name = m.name.as_deref().unwrap_or("?");
                scalars(module, m.ty, &under(name), base + m.offset, out);
            }
        }
        TypeInner::Array {
            base: element,
            size: ArraySize::Constant(count),
            stride,
        } => {
            for k in 0..count.get() {
                scalars(
                    module,
                    *element,
                    &under(&k.to_string()),
                    base + k * stride,
                    out,
                );
            }
        }
        other => panic!("no transcoding for {other:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::gpu::layout::{GpuMonomerAux, GpuParams, GpuWall};

    fn engine() -> &'static Transcoder {
        Transcoder::engine()
    }

    #[test]
    fn vectors_halve_and_keep_their_order() {
        let t = engine().element(Binding::Position);
        assert_eq!((t.exact_stride, t.mixed_stride), (32, 16));
        let host: Vec<u8> = bytemuck::cast_slice(&[[1.5f64, -2.0, 1e-9, 0.0], [3.0; 4]]).to_vec();
        let device = t.encode(&host);
        let floats: &[f32] = bytemuck::cast_slice(&device);
        assert_eq!(floats, &[1.5, -2.0, 1e-9, 0.0, 3.0, 3.0, 3.0, 3.0]);
        // 1e-9 is not an f32: it comes back as the nearest one.
        let back: Vec<f64> = bytemuck::pod_collect_to_vec(&t.decode(&device));
        assert_eq!(back[..2], [1.5, -2.0]);
        assert_eq!(back[2], f64::from(1e-9f32));
        assert_ne!(back[2], 1e-9);
    }

    #[test]
    fn words_are_copied_and_f64_beyond_f32_saturate() {
        let flags = engine().element(Binding::Flags);
        assert_eq!((flags.exact_stride, flags.mixed_stride), (4, 4));
        let words = bytemuck::cast_slice(&[7u32, u32::MAX]).to_vec();
        assert_eq!(flags.encode(&words), words);
        let diag = engine().element(Binding::Diag);
        let host = bytemuck::cast_slice(&[1e300f64, -1e300, f64::INFINITY]).to_vec();
        let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&diag.encode(&host));
        assert_eq!(floats, [f32::MAX, -f32::MAX, f32::INFINITY]);
    }

    #[test]
    fn structs_map_field_by_field_with_their_integers_intact() {
        // The params: u32 fields copied, f64 fields narrowed, at the f32 text's offsets.
        let t = engine().element(Binding::Params);
        assert_eq!(t.exact_stride as usize, std::mem::size_of::<GpuParams>());
        assert!(t.mixed_stride < t.exact_stride);
        let mut params: GpuParams = bytemuck::Zeroable::zeroed();
        params.n = 1234;
        params.dt = 3e-10;
        params.radius = 6e-5;
        let host = bytemuck::bytes_of(&params);
        let back: GpuParams = *bytemuck::from_bytes(&t.decode(&t.encode(host)));
        assert_eq!(back.n, 1234);
        assert_eq!(back.dt, f64::from(3e-10f32));
        assert_eq!(back.radius, f64::from(6e-5f32));
        for (binding, size) in [
            (Binding::Walls, std::mem::size_of::<GpuWall>()),
            (Binding::Aux, std::mem::size_of::<GpuMonomerAux>()),
        ] {
            assert_eq!(engine().element(binding).exact_stride as usize, size);
        }
    }

    #[test]
    fn offsets_and_sizes_follow_the_element_boundaries() {
        let diag = engine().element(Binding::Diag);
        assert_eq!(diag.mixed_offset(80), 40);
        assert_eq!(diag.mixed_bytes(24), 12);
        let position = engine().element(Binding::Position);
        assert_eq!(position.mixed_bytes(64), 32);
        assert_eq!(position.mixed_bytes(40), 32);
    }

    #[test]
    #[should_panic(expected = "inside an element")]
    fn an_offset_inside_an_element_is_refused() {
        engine().element(Binding::Position).mixed_offset(8);
    }

    #[test]
    fn pointers_carry_their_low_part_in_the_members_the_f32_text_adds() {
        // ContactPointer: [x, y, z, twist] on the host; hi, twist, lo on the device.
        let t = engine().element(Binding::WallN1);
        assert_eq!((t.exact_stride, t.mixed_stride), (32, 32));
        let n = [0.6f64, -0.8 + 1e-12, 1e-9, 0.25];
        let device = t.encode(bytemuck::cast_slice(&n));
        let f: &[f32] = bytemuck::cast_slice(&device);
        assert_eq!(f[..4], [0.6f32, (-0.8 + 1e-12) as f32, 1e-9f32, 0.25]);
        assert_eq!(f64::from(f[4]), (0.6 - f64::from(0.6f32)) as f32 as f64);
        let back: Vec<f64> = bytemuck::pod_collect_to_vec(&t.decode(&device));
        for k in 0..3 {
            // hi + lo holds 48 bits: the round trip is within 2⁻⁴⁸ of the f64.
            assert!(
                (back[k] - n[k]).abs() <= n[k].abs() * 2f64.powi(-47),
                "{k}: {}",
                back[k]
            );
        }
        assert_ne!(back[1], f64::from((-0.8 + 1e-12) as f32));
        assert_eq!(back[3], 0.25);
        // The partner's pointer has no twist: n then n_lo.
        let second = engine().element(Binding::PairN2Chunk0);
        assert_eq!((second.exact_stride, second.mixed_stride), (32, 32));
    }
}
