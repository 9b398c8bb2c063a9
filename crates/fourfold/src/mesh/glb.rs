//! A slice's mesh as binary glTF (GLB), by the gltf crate: one buffer of the positions
//! (f32) then the indices (u32), a view and an accessor for each, one triangle mesh in one
//! node of one scene. glTF's unit is the metre; the caller scales.

use gltf::json::validation::Checked::Valid;
use gltf::json::validation::USize64;
use gltf::json::{self, Index, accessor, buffer, mesh};

use super::SliceMesh;

/// The GLB file of `m`, its coordinates times `scale`, named by `comment`'s first line.
pub fn glb(m: &SliceMesh, scale: f64, comment: &str) -> Result<Vec<u8>, gltf::Error> {
    let positions: Vec<[f32; 3]> = m
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
    bin.extend(m.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("fourfold {}", env!("CARGO_PKG_VERSION"))),
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
    let position_view = view(
        &mut root,
        buffer,
        0..index_offset,
        buffer::Target::ArrayBuffer,
    );
    let index_view = view(
        &mut root,
        buffer,
        index_offset..bin.len(),
        buffer::Target::ElementArrayBuffer,
    );
    let positions = root.push(accessor(
        position_view,
        positions.len(),
        accessor::ComponentType::F32,
        accessor::Type::Vec3,
        Some(bounds(&positions)),
    ));
    let indices = root.push(accessor(
        index_view,
        3 * m.triangles.len(),
        accessor::ComponentType::U32,
        accessor::Type::Scalar,
        None,
    ));
    let name = comment.lines().next().map(String::from);
    scene_of(&mut root, positions, indices, name);
    let text = json::serialize::to_vec(&root)?;
    gltf::binary::Glb {
        // The length is the one `to_vec` writes, both chunks padded to four bytes.
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: std::borrow::Cow::Owned(text),
        bin: Some(std::borrow::Cow::Owned(bin)),
    }
    .to_vec()
}

/// One triangle mesh of these accessors, in one node of the file's one scene.
fn scene_of(
    root: &mut json::Root,
    positions: Index<json::Accessor>,
    indices: Index<json::Accessor>,
    name: Option<String>,
) {
    let primitive = mesh::Primitive {
        attributes: [(Valid(mesh::Semantic::Positions), positions)].into(),
        extensions: None,
        extras: Default::default(),
        indices: Some(indices),
        material: None,
        mode: Valid(mesh::Mode::Triangles),
        targets: None,
    };
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
}

/// A view of the bytes `range` of the buffer.
fn view(
    root: &mut json::Root,
    buffer: Index<json::Buffer>,
    range: std::ops::Range<usize>,
    target: buffer::Target,
) -> Index<buffer::View> {
    root.push(buffer::View {
        buffer,
        byte_length: USize64::from(range.len()),
        byte_offset: Some(USize64::from(range.start)),
        byte_stride: None,
        extensions: None,
        extras: Default::default(),
        name: None,
        target: Some(Valid(target)),
    })
}

/// An accessor of `count` items of a view, with its bounds where given (glTF asks them
/// of positions).
fn accessor(
    view: Index<buffer::View>,
    count: usize,
    component: accessor::ComponentType,
    kind: accessor::Type,
    bounds: Option<([f32; 3], [f32; 3])>,
) -> json::Accessor {
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
}

/// The smallest and largest of each coordinate.
fn bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    points.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|a| lo[a].min(p[a])),
                std::array::from_fn(|a| hi[a].max(p[a])),
            )
        },
    )
}
