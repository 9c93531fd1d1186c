//! The independent readers: a LAMMPS dump split into its `ITEM:` sections, `vtkio` for the
//! VTU, and plain string scanning for FieldData and XML comments.

use std::fs;
use std::path::Path;
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece, VertexNumbers};
use vtkio::Vtk;

/// A LAMMPS text dump split into `ITEM:` sections, each a header line and its body lines.
pub(crate) struct Dump {
    pub(crate) sections: Vec<(String, Vec<String>)>,
}

impl Dump {
    pub(crate) fn read(path: &Path) -> Dump {
        let text = fs::read_to_string(path).unwrap();
        let mut sections: Vec<(String, Vec<String>)> = Vec::new();
        for line in text.lines() {
            if let Some(header) = line.strip_prefix("ITEM: ") {
                sections.push((header.to_string(), Vec::new()));
            } else {
                sections
                    .last_mut()
                    .expect("dump must start with an ITEM: line")
                    .1
                    .push(line.to_string());
            }
        }
        Dump { sections }
    }

    pub(crate) fn section(&self, prefix: &str) -> (&str, &[String]) {
        let found: Vec<_> = self
            .sections
            .iter()
            .filter(|(h, _)| h == prefix || h.starts_with(&format!("{prefix} ")))
            .collect();
        assert_eq!(found.len(), 1, "expected exactly one ITEM: {prefix}");
        (&found[0].0, &found[0].1)
    }

    pub(crate) fn single(&self, item: &str) -> String {
        let (_, body) = self.section(item);
        assert_eq!(body.len(), 1, "ITEM: {item} must have one value line");
        body[0].trim().to_string()
    }
}

pub(crate) struct VtuRead {
    pub(crate) points: Vec<f64>,
    pub(crate) point_data: Vec<(String, IOBuffer)>,
    pub(crate) connectivity: Vec<u64>,
    pub(crate) offsets: Vec<u64>,
    pub(crate) types: Vec<vtkio::model::CellType>,
}

pub(crate) fn read_vtu(path: &Path) -> VtuRead {
    let vtk = Vtk::import(path).expect("vtkio cannot read the .vtu");
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid");
    };
    assert_eq!(pieces.len(), 1);
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("piece not inline");
    };
    let IOBuffer::F64(points) = piece.points else {
        panic!("points are not Float64");
    };
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = piece.cells.cell_verts
    else {
        panic!("cells not in XML layout");
    };
    let point_data = piece
        .data
        .point
        .into_iter()
        .map(|a| match a {
            Attribute::DataArray(a) => (a.name, a.data),
            Attribute::Field { name, .. } => panic!("unexpected field attribute {name}"),
        })
        .collect();
    VtuRead {
        points,
        point_data,
        connectivity,
        offsets,
        types: piece.cells.types,
    }
}

impl VtuRead {
    pub(crate) fn array(&self, name: &str) -> &IOBuffer {
        &self
            .point_data
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no point data {name}"))
            .1
    }
}

/// The text content of the first `<DataArray ... Name="name" ...>` element, split on
/// whitespace. vtkio does not expose FieldData, so this reads it by plain string search.
pub(crate) fn data_array_text(xml: &str, name: &str) -> Vec<String> {
    let key = format!("Name=\"{name}\"");
    let at = xml.find(&key).unwrap_or_else(|| panic!("no array {name}"));
    let open_end = at + xml[at..].find('>').unwrap() + 1;
    let close = open_end + xml[open_end..].find("</DataArray>").unwrap();
    xml[open_end..close]
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

/// XML forbids `--` inside comments; VTK's expat parser rejects such a file, while vtkio's
/// quick-xml lets it through, so this is checked separately.
pub(crate) fn assert_comments_well_formed(xml: &str) {
    for part in xml.split("<!--").skip(1) {
        let body = &part[..part.find("-->").expect("unterminated comment")];
        assert!(!body.contains("--"), "'--' inside comment: {body}");
        assert!(!body.ends_with('-'), "comment ends in '-': {body}");
    }
}
