//! Writing a slice's mesh: binary STL (stl_io), Wavefront OBJ (text) and binary PLY
//! (ply-rs-bw), its coordinates multiplied by a scale (1: the frame's own units).

use std::io::Write;

use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};

use super::SliceMesh;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    Stl,
    Obj,
    Ply,
    /// Binary glTF: one mesh of positions and indices, for Blender, three.js and the web.
    Glb,
}

impl MeshFormat {
    /// The format a file name's extension names.
    pub fn from_path(path: &std::path::Path) -> Result<Self, String> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("stl") => Ok(Self::Stl),
            Some("obj") => Ok(Self::Obj),
            Some("ply") => Ok(Self::Ply),
            Some("glb") => Ok(Self::Glb),
            _ => Err(format!(
                "'{}' has no mesh extension: write a .stl, .obj, .ply or .glb file",
                path.display()
            )),
        }
    }
}

impl SliceMesh {
    /// Writes the mesh in `format`, its coordinates times `scale`; `comment` goes in the
    /// file where the format has room for one (OBJ, PLY).
    pub fn write(
        &self,
        format: MeshFormat,
        scale: f64,
        comment: &str,
        out: &mut impl Write,
    ) -> std::io::Result<()> {
        let at = |i: u32| self.vertices[i as usize].map(|x| (x * scale) as f32);
        match format {
            MeshFormat::Stl => {
                let triangles = self.triangles.iter().map(|t| {
                    let [a, b, c] = t.map(at);
                    let n = super::contour::unit(super::cross(
                        super::sub(b.map(f64::from), a.map(f64::from)),
                        super::sub(c.map(f64::from), a.map(f64::from)),
                    ));
                    stl_io::Triangle {
                        normal: stl_io::Normal::new(n.map(|x| x as f32)),
                        vertices: [a, b, c].map(stl_io::Vertex::new),
                    }
                });
                stl_io::write_stl(out, triangles)
            }
            MeshFormat::Obj => {
                let mut out = std::io::BufWriter::new(out);
                for line in comment.lines() {
                    writeln!(out, "# {line}")?;
                }
                for i in 0..self.vertices.len() as u32 {
                    let [x, y, z] = at(i);
                    writeln!(out, "v {x} {y} {z}")?;
                }
                for [a, b, c] in &self.triangles {
                    writeln!(out, "f {} {} {}", a + 1, b + 1, c + 1)?;
                }
                out.flush()
            }
            MeshFormat::Ply => {
                let mut ply = self.ply(scale, comment);
                ply_rs_bw::writer::Writer::new()
                    .write_ply(out, &mut ply)
                    .map(|_| ())
            }
            MeshFormat::Glb => {
                let bytes = super::glb::glb(self, scale, comment).map_err(std::io::Error::other)?;
                out.write_all(&bytes)
            }
        }
    }

    fn ply(&self, scale: f64, comment: &str) -> Ply<DefaultElement> {
        let mut ply = Ply::<DefaultElement>::new();
        ply.header.encoding = Encoding::BinaryLittleEndian;
        ply.header
            .comments
            .extend(comment.lines().map(String::from));
        let mut vertex = ElementDef::new("vertex".to_string());
        for name in ["x", "y", "z"] {
            vertex.properties.add(PropertyDef::new(
                name.to_string(),
                PropertyType::Scalar(ScalarType::Float),
            ));
        }
        ply.header.elements.add(vertex);
        let mut face = ElementDef::new("face".to_string());
        face.properties.add(PropertyDef::new(
            "vertex_indices".to_string(),
            PropertyType::List(ScalarType::UChar, ScalarType::Int),
        ));
        ply.header.elements.add(face);
        let vertices = self
            .vertices
            .iter()
            .map(|v| {
                let mut e = DefaultElement::new();
                for (name, x) in ["x", "y", "z"].iter().zip(v) {
                    e.insert(name.to_string(), Property::Float((x * scale) as f32));
                }
                e
            })
            .collect();
        let faces = self
            .triangles
            .iter()
            .map(|t| {
                let mut e = DefaultElement::new();
                e.insert(
                    "vertex_indices".to_string(),
                    Property::ListInt(t.iter().map(|&i| i as i32).collect()),
                );
                e
            })
            .collect();
        ply.payload.insert("vertex".to_string(), vertices);
        ply.payload.insert("face".to_string(), faces);
        ply
    }
}
