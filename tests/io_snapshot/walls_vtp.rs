//! The walls' `.vtp`: each wall clipped to the box as a convex polygon wound about its normal.

use super::readers::assert_comments_well_formed;
use super::*;
use dustdem::output::snapshot::write_walls_vtp;
use std::path::Path;
use vtkio::model::{Attribute, DataSet, Piece, VertexNumbers};
use vtkio::Vtk;

/// Reads a `.vtp` written by `write_walls_vtp` through vtkio: polygons with their wall index
/// and normal.
fn read_walls_vtp(path: &Path) -> Vec<(i32, [f64; 3], Vec<[f64; 3]>)> {
    let vtk = Vtk::import(path).expect("vtkio cannot read the .vtp");
    let DataSet::PolyData { pieces, .. } = vtk.data else {
        panic!("not poly data");
    };
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("piece not inline");
    };
    let points = piece.points.cast_into::<f64>().unwrap();
    let Some(VertexNumbers::XML {
        connectivity,
        offsets,
    }) = piece.polys
    else {
        panic!("no polys");
    };
    let mut wall = Vec::new();
    let mut normal = Vec::new();
    for a in piece.data.cell {
        let Attribute::DataArray(a) = a else {
            panic!("field attribute")
        };
        match a.name.as_str() {
            "wall" => wall = a.data.cast_into::<i32>().unwrap(),
            "normal" => normal = a.data.cast_into::<f64>().unwrap(),
            other => panic!("unexpected cell data {other}"),
        }
    }
    let mut start = 0usize;
    offsets
        .iter()
        .enumerate()
        .map(|(c, &end)| {
            let poly = connectivity[start..end as usize]
                .iter()
                .map(|&v| {
                    let v = v as usize;
                    [points[3 * v], points[3 * v + 1], points[3 * v + 2]]
                })
                .collect();
            start = end as usize;
            (
                wall[c],
                [normal[3 * c], normal[3 * c + 1], normal[3 * c + 2]],
                poly,
            )
        })
        .collect()
}

#[test]
fn walls_are_clipped_to_the_box_and_wound_about_their_normal() {
    let dir = TempDir::new("vtp");
    // Box 0..2 x 0..2 x 0..1 cm = 0..2e4 x 0..2e4 x 0..1e4 µm.
    let extent = ([0.0, 0.0, 0.0], [2.0, 2.0, 1.0]);
    let walls = vec![
        // Lies exactly on the bottom face.
        WallPlane {
            name: "floor".into(),
            point: [5.0, 5.0, 0.0],
            normal: [0.0, 0.0, 1.0],
        },
        // Misses the box.
        WallPlane {
            name: "far".into(),
            point: [0.0, 0.0, 3.0],
            normal: [0.0, 0.0, -1.0],
        },
        // Through the centre, perpendicular to the space diagonal: a hexagon.
        WallPlane {
            name: "diag---".into(),
            point: [1.0, 1.0, 0.5],
            normal: [1.0, 1.0, 1.0],
        },
        // Only touches the box at one corner.
        WallPlane {
            name: "corner".into(),
            point: [2.0, 2.0, 1.0],
            normal: [-1.0, -1.0, -1.0],
        },
        // Shaves the top corner by far less than the box size: the three cut points are
        // numerically one point, and must not become a degenerate sliver polygon.
        WallPlane {
            name: "shave".into(),
            point: [2.0 - 1.0e-11, 2.0, 1.0],
            normal: [-1.0, -1.0, -1.0],
        },
    ];
    let path = dir.path("walls.vtp");
    write_walls_vtp(&path, &walls, extent).unwrap();
    assert_comments_well_formed(&fs::read_to_string(&path).unwrap());
    let polys = read_walls_vtp(&path);

    assert_eq!(
        polys.iter().map(|p| (p.0, p.2.len())).collect::<Vec<_>>(),
        vec![(0, 4), (2, 6)]
    );
    let floor = &polys[0].2;
    let mut corners: Vec<[f64; 3]> = floor.clone();
    corners.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(
        corners,
        vec![
            [0.0, 0.0, 0.0],
            [0.0, 2.0e4, 0.0],
            [2.0e4, 0.0, 0.0],
            [2.0e4, 2.0e4, 0.0]
        ]
    );

    for (w, n, poly) in &polys {
        let wall = &walls[*w as usize];
        let len = wall.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        let unit = [
            wall.normal[0] / len,
            wall.normal[1] / len,
            wall.normal[2] / len,
        ];
        for k in 0..3 {
            assert!((n[k] - unit[k]).abs() < 1e-15);
        }
        let p = [
            wall.point[0] * UM_PER_CM,
            wall.point[1] * UM_PER_CM,
            wall.point[2] * UM_PER_CM,
        ];
        for q in poly {
            let dist: f64 = (0..3).map(|k| (q[k] - p[k]) * unit[k]).sum();
            assert!(dist.abs() < 1e-9, "vertex {q:?} off the plane by {dist}");
            for (k, &x) in q.iter().enumerate() {
                let tol = 1e-9;
                assert!(
                    x >= extent.0[k] * UM_PER_CM - tol,
                    "vertex {q:?} outside the box"
                );
                assert!(
                    x <= extent.1[k] * UM_PER_CM + tol,
                    "vertex {q:?} outside the box"
                );
            }
        }
        // Newell's formula: the polygon's own normal must point along the wall normal, and
        // a convex polygon traversed in order has all edge turns on the same side.
        let m = poly.len();
        let mut area = [0.0; 3];
        for i in 0..m {
            let (a, b) = (poly[i], poly[(i + 1) % m]);
            area[0] += (a[1] - b[1]) * (a[2] + b[2]);
            area[1] += (a[2] - b[2]) * (a[0] + b[0]);
            area[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        let along: f64 = (0..3).map(|k| area[k] * unit[k]).sum();
        assert!(along > 0.0, "wall {w} wound against its normal");
        for i in 0..m {
            let (a, b, c) = (poly[i], poly[(i + 1) % m], poly[(i + 2) % m]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - b[0], c[1] - b[1], c[2] - b[2]];
            let turn = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let t: f64 = (0..3).map(|k| turn[k] * unit[k]).sum();
            assert!(t > 0.0, "wall {w} polygon not convex/ordered at vertex {i}");
        }
    }
}

#[test]
fn walls_vtp_without_polygons_is_still_valid() {
    let dir = TempDir::new("vtp-empty");
    let path = dir.path("none.vtp");
    write_walls_vtp(&path, &[], ([0.0; 3], [1.0; 3])).unwrap();
    let xml = fs::read_to_string(&path).unwrap();
    assert!(xml.contains(r#"NumberOfPoints="0""#) && xml.contains(r#"NumberOfPolys="0""#));
    assert!(write_walls_vtp(&path, &[], ([1.0; 3], [0.0; 3])).is_err());
}
