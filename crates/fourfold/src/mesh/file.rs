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
                let bytes = self.glb(scale, comment).map_err(std::io::Error::other)?;
                out.write_all(&bytes)
            }
        }
    }

    /// The binary glTF file: a buffer of the positions (f32) then the indices (u32), a
    /// view and an accessor for each, one triangle mesh in one node of one scene.
    fn glb(&self, scale: f64, comment: &str) -> Result<Vec<u8>, gltf::Error> {
        use gltf::json::validation::Checked::Valid;
        use gltf::json::validation::USize64;
        use gltf::json::{self, accessor, buffer, mesh};
        let positions: Vec<[f32; 3]> = self
            .vertices
            .iter()
            .map(|v| v.map(|x| (x * scale) as f32))
            .collect();
        let mut bin: Vec<u8> = positions
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let index_offset = bin.len();
        bin.extend(
            self.triangles
                .iter()
                .flatten()
                .flat_map(|i| i.to_le_bytes()),
        );
        let (lo, hi) = positions.iter().fold(
            ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    std::array::from_fn(|a| lo[a].min(p[a])),
                    std::array::from_fn(|a| hi[a].max(p[a])),
                )
            },
        );
        let mut root = json::Root {
            asset: json::Asset {
                generator: Some(format!("fourfold {}", env!("CARGO_PKG_VERSION"))),
                copyright: None,
                ..Default::default()
            },
            ..Default::default()
        };
        let buffer = root.push(json::Buffer {
            byte_length: USize64::from(bin.len()),
            extensions: None,
            extras: Default::default(),
            name: None,
            uri: None,
        });
        let view = |root: &mut json::Root, offset: usize, length: usize, target| {
            root.push(buffer::View {
                buffer,
                byte_length: USize64::from(length),
                byte_offset: Some(USize64::from(offset)),
                byte_stride: None,
                extensions: None,
                extras: Default::default(),
                name: None,
                target: Some(Valid(target)),
            })
        };
        let position_view = view(&mut root, 0, index_offset, buffer::Target::ArrayBuffer);
        let index_view = view(
            &mut root,
            index_offset,
            bin.len() - index_offset,
            buffer::Target::ElementArrayBuffer,
        );
        let accessor =
            |view, count: usize, component, kind, bounds: Option<([f32; 3], [f32; 3])>| {
                json::Accessor {
                    buffer_view: Some(view),
                    byte_offset: None,
                    count: USize64::from(count),
                    component_type: Valid(accessor::GenericComponentType(component)),
                    extensions: None,
                    extras: Default::default(),
                    type_: Valid(kind),
                    min: bounds.map(|(lo, _)| json::Value::from(lo.to_vec())),
                    max: bounds.map(|(_, hi)| json::Value::from(hi.to_vec())),
                    name: None,
                    normalized: false,
                    sparse: None,
                }
            };
        let position_accessor = root.push(accessor(
            position_view,
            positions.len(),
            accessor::ComponentType::F32,
            accessor::Type::Vec3,
            Some((lo, hi)),
        ));
        let index_accessor = root.push(accessor(
            index_view,
            3 * self.triangles.len(),
            accessor::ComponentType::U32,
            accessor::Type::Scalar,
            None,
        ));
        let primitive = mesh::Primitive {
            attributes: [(Valid(mesh::Semantic::Positions), position_accessor)].into(),
            extensions: None,
            extras: Default::default(),
            indices: Some(index_accessor),
            material: None,
            mode: Valid(mesh::Mode::Triangles),
            targets: None,
        };
        let name = comment.lines().next().map(String::from);
        let the_mesh = root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: name.clone(),
            primitives: vec![primitive],
            weights: None,
        });
        let node = root.push(json::Node {
            mesh: Some(the_mesh),
            name,
            ..Default::default()
        });
        let scene = root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes: vec![node],
        });
        root.scene = Some(scene);
        let text = json::serialize::to_vec(&root)?;
        gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                // Filled in by `to_vec`, which pads both chunks to four bytes.
                length: 0,
            },
            json: std::borrow::Cow::Owned(text),
            bin: Some(std::borrow::Cow::Owned(bin)),
        }
        .to_vec()
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
