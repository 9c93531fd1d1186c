//! The VTK XML unstructured grid (`.vtu`) of one snapshot, for ParaView.

use super::format::*;
use super::{Snapshot, CM_TO_UM};
use std::io::{self, Write};

pub(super) fn vtu_body<W: Write>(w: &mut W, s: &Snapshot) -> io::Result<()> {
    let n = s.positions.len();
    let r_um = s.radius * CM_TO_UM;
    // Only a failed-state snapshot gets this far with non-finite values (write_failed_vtu).
    // The conversions to µm and m/s can overflow finite values too; those count as well.
    let finite: Vec<bool> = (0..n)
        .map(|i| {
            monomer_is_finite(s, i)
                && scale(s.positions[i], CM_TO_UM)
                    .iter()
                    .all(|x| x.is_finite())
        })
        .collect();
    let all_finite = finite.iter().all(|&f| f);
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        "<!-- dustdem snapshot: step {}, time {} s",
        s.step,
        F(s.time)
    )?;
    writeln!(
        w,
        "     units: points and radius in um, velocity in m/s, angular_velocity in rad/s, \
         time in s"
    )?;
    writeln!(
        w,
        "     id = monomer index + 1, the same id as in the LAMMPS dump"
    )?;
    wall_comment(w, s.walls, "     ")?;
    if !all_finite {
        writeln!(
            w,
            "     failed state: {} of {n} monomers hold a non-finite value (NaN or inf); arrays \
             holding one are in binary, and point array finite = 0 marks those monomers",
            finite.iter().filter(|&&f| !f).count()
        )?;
    }
    writeln!(w, "-->")?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian"{}>"#,
        if all_finite {
            ""
        } else {
            r#" header_type="UInt64""#
        }
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;

    writeln!(w, "    <FieldData>")?;
    writeln!(
        w,
        r#"      <DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">{}</DataArray>"#,
        F(s.time)
    )?;
    writeln!(
        w,
        r#"      <DataArray type="UInt64" Name="step" NumberOfTuples="1" format="ascii">{}</DataArray>"#,
        s.step
    )?;
    // Zero-tuple arrays upset some readers, so without walls there are simply no wall arrays.
    if !s.walls.is_empty() {
        for (name, values) in [
            (
                "wall_point",
                s.walls
                    .iter()
                    .map(|wall| scale(wall.point, CM_TO_UM))
                    .collect::<Vec<_>>(),
            ),
            (
                "wall_normal",
                s.walls.iter().map(|wall| unit(wall.normal)).collect(),
            ),
        ] {
            writeln!(
                w,
                r#"      <DataArray type="Float64" Name="{name}" NumberOfComponents="3" NumberOfTuples="{}" format="ascii">"#,
                values.len()
            )?;
            for v in values {
                writeln!(w, "        {}", V3(v))?;
            }
            writeln!(w, "      </DataArray>")?;
        }
    }
    writeln!(w, "    </FieldData>")?;

    writeln!(w, r#"    <Piece NumberOfPoints="{n}" NumberOfCells="{n}">"#)?;
    writeln!(
        w,
        r#"      <PointData Scalars="radius" Vectors="velocity">"#
    )?;
    scalar_array(w, "Int64", "id", (1..=n as u64).map(|id| id as i64))?;
    vector_array(w, "velocity", s.velocities.iter().map(|&v| to_m_per_s(v)))?;
    vector_array(w, "angular_velocity", s.angular_velocities.iter().copied())?;
    scalar_array(w, "Float64", "radius", (0..n).map(|_| F(r_um)))?;
    scalar_array(w, "UInt32", "contacts", s.contacts.iter())?;
    if !all_finite {
        scalar_array(w, "UInt8", "finite", finite.iter().map(|&f| u8::from(f)))?;
    }
    writeln!(w, "      </PointData>")?;
    writeln!(w, "      <Points>")?;
    vector_array(
        w,
        "position",
        s.positions.iter().map(|&p| scale(p, CM_TO_UM)),
    )?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Cells>")?;
    scalar_array(w, "Int64", "connectivity", 0..n as u64)?;
    scalar_array(w, "Int64", "offsets", 1..=n as u64)?;
    // 1 = VTK_VERTEX: each monomer is a cell of its own, so ParaView renders the points
    // without a filter and cell-based filters see every monomer.
    scalar_array(w, "UInt8", "types", (0..n).map(|_| 1u8))?;
    writeln!(w, "      </Cells>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")
}
