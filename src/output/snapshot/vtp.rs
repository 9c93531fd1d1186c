//! The walls as polygons (`.vtp`): each plane clipped to a box, for ParaView.

use super::format::*;
use super::{WallPlane, CM_TO_UM};
use std::io::{self, Write};

/// Where one wall cuts the box.
pub(super) struct WallPolygon {
    /// Index into the caller's walls.
    pub(super) wall: usize,
    /// Unit normal, into the domain.
    pub(super) normal: [f64; 3],
    /// cm, counter-clockwise about `normal`.
    pub(super) vertices: Vec<[f64; 3]>,
}

/// The polygon in which the plane through `p` with unit normal `n` cuts the box `[lo, hi]`,
/// in cm, wound counter-clockwise about `n`. Fewer than three vertices when the plane
/// misses the box or only grazes an edge or a corner.
pub(super) fn clip_plane_to_box(
    p: [f64; 3],
    n: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
) -> Vec<[f64; 3]> {
    let size = dot(sub(hi, lo), sub(hi, lo)).sqrt();
    // Distances below this count as "on the plane", so that a wall lying exactly on a face
    // of the box (the usual floor) yields that face rather than a sliver or nothing.
    let eps = 1.0e-12 * size;
    let corner = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let dist: Vec<f64> = (0..8).map(|i| dot(n, sub(corner(i), p))).collect();

    let mut pts: Vec<[f64; 3]> = Vec::new();
    for (i, d) in dist.iter().enumerate() {
        if d.abs() <= eps {
            pts.push(corner(i));
        }
    }
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit != 0 {
                continue;
            }
            let j = i | bit;
            let (da, db) = (dist[i], dist[j]);
            if da.abs() > eps && db.abs() > eps && (da < 0.0) != (db < 0.0) {
                let t = da / (da - db);
                let (a, b) = (corner(i), corner(j));
                pts.push([
                    a[0] + t * (b[0] - a[0]),
                    a[1] + t * (b[1] - a[1]),
                    a[2] + t * (b[2] - a[2]),
                ]);
            }
        }
    }

    // A corner on the plane is reached from several edges; keep it once.
    let merge = 1.0e-9 * size;
    let mut unique: Vec<[f64; 3]> = Vec::with_capacity(pts.len());
    for q in pts {
        if unique.iter().all(|u| {
            let d = sub(q, *u);
            dot(d, d).sqrt() > merge
        }) {
            unique.push(q);
        }
    }
    if unique.len() < 3 {
        return Vec::new();
    }

    // In-plane basis (u, v) with u x v = n, so ascending angle is counter-clockwise about n.
    let k = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let u = unit(cross(n, e));
    let v = cross(n, u);
    let m = unique.len() as f64;
    let c = unique.iter().fold([0.0; 3], |acc, q| {
        [acc[0] + q[0] / m, acc[1] + q[1] / m, acc[2] + q[2] / m]
    });
    let angle = |q: &[f64; 3]| {
        let d = sub(*q, c);
        dot(d, v).atan2(dot(d, u))
    };
    unique.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
    unique
}

pub(super) fn vtp_body<W: Write>(
    w: &mut W,
    walls: &[WallPlane],
    polygons: &[WallPolygon],
) -> io::Result<()> {
    let n_points: usize = polygons.iter().map(|p| p.vertices.len()).sum();
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        "<!-- dustdem walls clipped to the domain's bounding box; points in um"
    )?;
    wall_comment(w, walls, "     ")?;
    writeln!(w, "     cell data wall = index in the list above -->")?;
    writeln!(
        w,
        r#"<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian">"#
    )?;
    writeln!(w, "  <PolyData>")?;
    writeln!(
        w,
        r#"    <Piece NumberOfPoints="{n_points}" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="{}">"#,
        polygons.len()
    )?;
    writeln!(w, "      <PointData>")?;
    writeln!(w, "      </PointData>")?;
    writeln!(w, r#"      <CellData Scalars="wall" Normals="normal">"#)?;
    scalar_array(w, "Int32", "wall", polygons.iter().map(|p| p.wall))?;
    vector_array(w, "normal", polygons.iter().map(|p| p.normal))?;
    writeln!(w, "      </CellData>")?;
    writeln!(w, "      <Points>")?;
    vector_array(
        w,
        "position",
        polygons
            .iter()
            .flat_map(|p| p.vertices.iter().map(|&q| scale(q, CM_TO_UM))),
    )?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Polys>")?;
    scalar_array(w, "Int64", "connectivity", 0..n_points as u64)?;
    scalar_array(
        w,
        "Int64",
        "offsets",
        polygons.iter().scan(0usize, |end, p| {
            *end += p.vertices.len();
            Some(*end)
        }),
    )?;
    writeln!(w, "      </Polys>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </PolyData>")?;
    writeln!(w, "</VTKFile>")
}
