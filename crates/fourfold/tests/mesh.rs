//! Meshes of slices, checked against what is known of the shapes: the glome's slice is a
//! round sphere, the spheritorus's a torus or two spheres, the 16-cell's an octahedron with
//! sharp edges; every mesh closed, a manifold, wound outward, its vertices in their cells;
//! each file format read back by a reader that is not the writer.

mod common;

use std::collections::HashMap;

use fourfold::CompiledFormula;
use fourfold::mesh::{MeshError, MeshFormat, MeshSettings, SliceMesh, mesh_slice};
use fourfold::render::view::Rotation4;
use fourfold::scene::{AxisRange, Domain, Scene};

use common::Rng;

fn mesh(scene: &Scene, settings: MeshSettings) -> Result<SliceMesh, MeshError> {
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    mesh_slice(&formula, scene, &settings)
}

fn scene(formula: &str, half: f64, angles: [f64; 6]) -> Scene {
    let mut scene = Scene::from_formula(formula);
    scene.domain = Domain::from_axes([AxisRange::new(-half, half).unwrap(); 4]);
    scene.view.angles = angles;
    scene
}

/// What a mesh is made of, topologically.
struct Topology {
    euler: i64,
    components: usize,
}

/// Checks that the mesh is closed, consistently wound, a manifold at every vertex, without
/// degenerate triangles, with every vertex inside its cell; returns its topology.
fn closed_manifold(m: &SliceMesh) -> Topology {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}-{b} is in {n} triangles the same way round");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} has no twin: a hole"
        );
    }
    // Around each vertex the triangles form one fan: a single loop of opposite edges.
    let mut fans: HashMap<u32, HashMap<u32, u32>> = HashMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            fans.entry(t[k])
                .or_default()
                .insert(t[(k + 1) % 3], t[(k + 2) % 3]);
        }
    }
    for (v, fan) in &fans {
        let start = *fan.keys().next().unwrap();
        let (mut at, mut steps) = (start, 0);
        loop {
            at = fan[&at];
            steps += 1;
            if at == start {
                break;
            }
        }
        assert_eq!(
            steps,
            fan.len(),
            "vertex {v}: its triangles form more than one fan"
        );
    }
    let side = m.grid.side;
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.vertices[i as usize]);
        let area = norm(cross(sub(b, a), sub(c, a))) / 2.0;
        assert!(
            area > 1e-9 * side * side,
            "a degenerate triangle {t:?}: {area}"
        );
    }
    for (v, cell) in m.vertices.iter().zip(&m.vertex_cells) {
        let lo = m.grid.corner(*cell);
        let hi = m.grid.corner(cell.map(|x| x + 1));
        assert!(
            (0..3).all(|a| lo[a] <= v[a] && v[a] <= hi[a]),
            "{v:?} outside its cell {lo:?}..{hi:?}"
        );
    }
    assert!(m.volume() > 0.0, "wound inward: volume {}", m.volume());
    // Components, by union-find over the triangles' edges.
    let mut parent: Vec<usize> = (0..m.vertices.len()).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for t in &m.triangles {
        for k in 0..2 {
            let (a, b) = (
                root(&mut parent, t[k] as usize),
                root(&mut parent, t[k + 1] as usize),
            );
            parent[a] = b;
        }
    }
    let components = (0..parent.len())
        .filter(|&i| root(&mut parent, i) == i)
        .count();
    let edges = directed.len() as i64 / 2;
    Topology {
        euler: m.vertices.len() as i64 - edges + m.triangles.len() as i64,
        components,
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] - b[i])
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[test]
fn the_glome_s_slice_is_a_round_sphere_in_any_view() {
    let mut rng = Rng(0x5eed_0036);
    for _ in 0..4 {
        let angles = std::array::from_fn(|_| rng.range(-3.0, 3.0));
        let c = rng.range(-0.8, 0.8);
        let s = scene("x^2 + y^2 + z^2 + w^2 = 1", 1.5, angles);
        let m = mesh(&s, MeshSettings::new(c)).unwrap();
        let topology = closed_manifold(&m);
        assert_eq!((topology.euler, topology.components), (2, 1), "c = {c}");
        let r = (1.0 - c * c).sqrt();
        let exact = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
        let error = (m.volume() - exact).abs() / exact;
        assert!(
            error < 0.005,
            "c = {c}: volume {} against {exact} ({error:.4})",
            m.volume()
        );
        let tolerance = m.stats.tolerance;
        for v in &m.vertices {
            assert!(
                (norm(*v) - r).abs() <= 1.01 * tolerance,
                "{v:?}: {} from r = {r}",
                norm(*v)
            );
        }
        assert_eq!(m.stats.over_tolerance, 0);
        assert!(m.stats.max_residual <= tolerance);
    }
}

#[test]
fn the_spheritorus_cuts_into_a_torus_across_and_two_spheres_along_its_circle() {
    let formula = "(sqrt(x^2 + y^2 + z^2) - 1)^2 + w^2 = 0.16";
    // n2 along x: the cut is (√(y²+z²) − 1)² + w² = 0.4², a torus.
    let across = [
        0.0,
        0.0,
        std::f64::consts::FRAC_PI_2,
        0.0,
        std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_2,
    ];
    let n2 = Rotation4::from_angles(across).row(3);
    assert!((n2[0].abs() - 1.0).abs() < 1e-12, "{n2:?}");
    let torus = mesh(&scene(formula, 1.6, across), MeshSettings::new(0.0)).unwrap();
    let t = closed_manifold(&torus);
    assert_eq!((t.euler, t.components), (0, 1));
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.16;
    assert!(
        (torus.volume() - exact).abs() / exact < 0.005,
        "{} against {exact}",
        torus.volume()
    );
    // n2 along w: a shell between the spheres of radii 0.6 and 1.4, two boundaries.
    let shell = mesh(&scene(formula, 1.6, [0.0; 6]), MeshSettings::new(0.0)).unwrap();
    let t = closed_manifold(&shell);
    assert_eq!((t.euler, t.components), (4, 2));
}

#[test]
fn the_16_cell_s_slice_keeps_its_flat_faces_and_sharp_edges() {
    // |x| + |y| + |z| ≤ 1 at w = 0: an octahedron, faces with normals (±1, ±1, ±1)/√3.
    let s = scene("abs(x) + abs(y) + abs(z) + abs(w) = 1", 1.2, [0.0; 6]);
    let m = mesh(&s, MeshSettings::new(0.0)).unwrap();
    let t = closed_manifold(&m);
    assert_eq!((t.euler, t.components), (2, 1));
    assert!((m.volume() - 4.0 / 3.0).abs() < 1e-3, "{}", m.volume());
    let normals: Vec<[f64; 3]> = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.vertices[i as usize]);
            let n = cross(sub(b, a), sub(c, a));
            n.map(|x| x / norm(n))
        })
        .collect();
    // The six corners are vertices of the mesh.
    let apexes: Vec<[f64; 3]> = (0..6)
        .map(|k| std::array::from_fn(|a| if a == k / 2 { [1.0, -1.0][k % 2] } else { 0.0 }))
        .collect();
    for apex in &apexes {
        let nearest = m
            .vertices
            .iter()
            .map(|v| norm(sub(*v, *apex)))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 1e-6,
            "corner {apex:?}: nearest vertex {nearest} away"
        );
    }
    // Away from the corners (where four faces meet within one cell, and the triangles
    // there join them), every triangle lies in a face: its normal is a face's to within a
    // degree; so across each edge the mesh is flat or bends by the octahedron's own angle.
    let near_apex = |t: &[u32; 3]| {
        t.iter().any(|&i| {
            let v = m.vertices[i as usize];
            apexes.iter().any(|a| norm(sub(v, *a)) < 3.0 * m.grid.side)
        })
    };
    let mut by_edge: HashMap<(u32, u32), usize> = HashMap::new();
    let (mut edges_checked, mut sharp) = (0, 0);
    for (k, t) in m.triangles.iter().enumerate() {
        if near_apex(t) {
            continue;
        }
        let n = normals[k];
        let best = n.iter().map(|x| x.abs()).sum::<f64>() / 3f64.sqrt();
        assert!(
            best > 1.0f64.to_radians().cos(),
            "{t:?} is off every face by {:.2}°",
            best.acos().to_degrees()
        );
        for j in 0..3 {
            let (a, b) = (t[j], t[(j + 1) % 3]);
            if let Some(other) = by_edge.insert((a.min(b), a.max(b)), k) {
                let cos = (0..3).map(|i| n[i] * normals[other][i]).sum::<f64>();
                let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
                let octahedron = (1.0f64 / 3.0).acos().to_degrees();
                assert!(angle < 2.0 || (angle - octahedron).abs() < 2.0, "{angle}°");
                edges_checked += 1;
                sharp += usize::from(angle > 2.0);
            }
        }
    }
    assert!(edges_checked > 90_000, "{edges_checked}");
    // The twelve edges, each about √2 / side cells long, are creases all along.
    let crease = 12.0 * 2f64.sqrt() / m.grid.side;
    assert!(
        sharp as f64 > 0.8 * crease,
        "{sharp} sharp mesh edges, against {crease:.0}"
    );
}

#[test]
fn a_cut_leaving_the_domain_is_capped_or_left_open() {
    // The half-space x < 0.3 in [-1, 1]⁴ at w = 0: capped, the box [-1, 0.3] × [-1, 1]².
    let s = scene("x = 0.3", 1.0, [0.0; 6]);
    let capped = mesh(&s, MeshSettings::new(0.0)).unwrap();
    let t = closed_manifold(&capped);
    assert_eq!((t.euler, t.components), (2, 1));
    assert!((capped.volume() - 5.2).abs() < 1e-6, "{}", capped.volume());
    // Open: the square x = 0.3 alone, a disc (χ = 1), facing +x.
    let open = mesh(
        &s,
        MeshSettings {
            caps: false,
            ..MeshSettings::new(0.0)
        },
    )
    .unwrap();
    let area: f64 = open
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| open.vertices[i as usize]);
            cross(sub(b, a), sub(c, a))[0] / 2.0
        })
        .sum();
    assert!((area - 4.0).abs() < 1e-6, "{area}");
    assert!(open.vertices.iter().all(|v| (v[0] - 0.3).abs() < 1e-9));
}

#[test]
fn a_slice_that_misses_says_why() {
    let s = scene("x^2 + y^2 + z^2 + w^2 = 1", 1.5, [0.0; 6]);
    let far = mesh(&s, MeshSettings::new(2.0)).unwrap_err();
    assert!(matches!(far, MeshError::Misses { .. }), "{far}");
    assert!(far.to_string().contains("misses the domain"), "{far}");
    let empty = mesh(&s, MeshSettings::new(1.2)).unwrap_err();
    assert_eq!(empty, MeshError::Empty { offset: 1.2 });
    let undefined = mesh(
        &scene("sqrt(-1 - x^2) = y", 1.0, [0.0; 6]),
        MeshSettings::new(0.0),
    );
    assert!(
        matches!(undefined, Err(MeshError::Empty { .. })),
        "{undefined:?}"
    );
    for (settings, said) in [
        (
            MeshSettings {
                max_level: 11,
                ..MeshSettings::new(0.0)
            },
            "within 1..=10",
        ),
        (
            MeshSettings {
                tolerance: Some(-1.0),
                ..MeshSettings::new(0.0)
            },
            "positive",
        ),
    ] {
        let e = mesh(&s, settings).unwrap_err().to_string();
        assert!(e.contains(said), "{e}");
    }
}

/// A binary STL's triangles, read by hand from the format's description.
fn read_stl(bytes: &[u8]) -> Vec<[[f32; 3]; 3]> {
    let count = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * count);
    let f = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    (0..count)
        .map(|k| {
            let base = 84 + 50 * k + 12;
            std::array::from_fn(|v| std::array::from_fn(|a| f(base + 12 * v + 4 * a)))
        })
        .collect()
}

/// A binary little-endian PLY's vertices and faces, read by hand from its header.
fn read_ply(bytes: &[u8]) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(
        header.contains("format binary_little_endian 1.0"),
        "{header}"
    );
    let count = |name: &str| -> usize {
        let line = header
            .lines()
            .find(|l| l.starts_with(&format!("element {name} ")))
            .unwrap();
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let (nv, nf) = (count("vertex"), count("face"));
    let mut at = end;
    let f32_at = |at: &mut usize| {
        let x = f32::from_le_bytes(bytes[*at..*at + 4].try_into().unwrap());
        *at += 4;
        x
    };
    let vertices = (0..nv)
        .map(|_| std::array::from_fn(|_| f32_at(&mut at)))
        .collect();
    let faces = (0..nf)
        .map(|_| {
            assert_eq!(bytes[at], 3);
            at += 1;
            std::array::from_fn(|_| {
                let i = i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
                at += 4;
                i as u32
            })
        })
        .collect();
    assert_eq!(at, bytes.len());
    (vertices, faces)
}

#[test]
fn every_format_reads_back_with_the_same_triangles() {
    let s = scene(
        "x^2 + y^2 + z^2 + w^2 = 1",
        1.5,
        [0.3, 0.5, 0.2, 0.0, 0.0, 0.0],
    );
    let m = mesh(
        &s,
        MeshSettings {
            max_level: 5,
            ..MeshSettings::new(0.3)
        },
    )
    .unwrap();
    let scale = 25.0;
    let want: Vec<[[f32; 3]; 3]> = m
        .triangles
        .iter()
        .map(|t| t.map(|i| m.vertices[i as usize].map(|x| (x * scale) as f32)))
        .collect();
    let write = |format| {
        let mut bytes = Vec::new();
        m.write(format, scale, "fourfold test\nglome", &mut bytes)
            .unwrap();
        bytes
    };
    assert_eq!(read_stl(&write(MeshFormat::Stl)), want);
    let (vertices, faces) = read_ply(&write(MeshFormat::Ply));
    let got: Vec<[[f32; 3]; 3]> = faces
        .iter()
        .map(|f| f.map(|i| vertices[i as usize]))
        .collect();
    assert_eq!(got, want);
    let obj = write(MeshFormat::Obj);
    let (models, _) = tobj::load_obj_buf(
        &mut std::io::Cursor::new(obj),
        &tobj::LoadOptions {
            triangulate: false,
            single_index: true,
            ..Default::default()
        },
        |_| Err(tobj::LoadError::OpenFileFailed),
    )
    .unwrap();
    let mesh = &models[0].mesh;
    let got: Vec<[[f32; 3]; 3]> = mesh
        .indices
        .chunks(3)
        .map(|f| {
            std::array::from_fn(|k| std::array::from_fn(|a| mesh.positions[3 * f[k] as usize + a]))
        })
        .collect();
    assert_eq!(got, want);
    // glTF: the gltf crate's validating reader, its accessors and bounds.
    let glb = write(MeshFormat::Glb);
    let gltf = gltf::Gltf::from_slice(&glb).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    let primitive = gltf.meshes().next().unwrap().primitives().next().unwrap();
    assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
    let reader = primitive.reader(|_| Some(blob));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let got: Vec<[[f32; 3]; 3]> = indices
        .chunks(3)
        .map(|f| std::array::from_fn(|k| positions[f[k] as usize]))
        .collect();
    assert_eq!(got, want);
    let bounds = primitive.bounding_box();
    for (a, p) in positions.iter().flatten().enumerate() {
        assert!(bounds.min[a % 3] <= *p && *p <= bounds.max[a % 3]);
    }
    assert_eq!(gltf.meshes().next().unwrap().name(), Some("fourfold test"));
}

#[test]
fn invented_slices_are_closed_solids_of_the_volume_sampling_finds() {
    // Formulas nobody tuned the mesher for: an undefined region, nested shells, kinks, a
    // log singularity, jumps, a parameter, thin saddles; in an oblique view. Each mesh is a
    // closed manifold wound outward, and its volume is what dense random sampling of the
    // slice finds inside (F < 0 in the domain), an estimate independent of the mesher.
    let angles = [0.4, 0.9, -0.3, 0.2, 1.1, 0.5];
    let cases = [
        "sqrt(1 - x^2 - y^2) - abs(z) - 0.3*w",
        "(x^2+y^2+z^2+w^2 - 1)*(x^2+y^2+z^2+w^2 - 0.81)",
        "max(abs(x) + abs(y), abs(z) + abs(w)) - 1",
        "ln(x^2 + y^2) + z",
        "floor(3*x) + floor(3*y) - z*3",
        "(sqrt(x^2 + y^2) - a)^2 + z^2 + w^2 - b^2",
        "x*y*z*w - 0.01",
    ];
    let mut rng = Rng(0x0bad_5eed);
    for formula in cases {
        let mut s = scene(formula, 2.0, angles);
        s.params.insert("a".into(), 1.1);
        s.params.insert("b".into(), 0.35);
        let m = mesh(
            &s,
            MeshSettings {
                max_level: 7,
                ..MeshSettings::new(0.13)
            },
        )
        .unwrap();
        closed_manifold(&m);
        let compiled = CompiledFormula::compile(formula).unwrap();
        let params = s.param_values(&compiled.param_names());
        let frame = fourfold::mesh::SliceFrame::new(&s.domain, &s.view, 0.13);
        let (lo, hi) = (m.grid.corner([0; 3]), m.grid.corner([m.grid.cells; 3]));
        let n = 200_000;
        let inside = (0..n)
            .filter(|_| {
                let u: [f64; 3] = std::array::from_fn(|a| rng.range(lo[a], hi[a]));
                let p = frame.point(u);
                common::eval_f(&compiled, p, &params) < 0.0 && frame.outside(p).0 < 0.0
            })
            .count();
        let whole: f64 = (0..3).map(|a| hi[a] - lo[a]).product();
        let share = inside as f64 / n as f64;
        let sampled = share * whole;
        let sigma = whole * (share * (1.0 - share) / n as f64).sqrt();
        let error = (m.volume() - sampled).abs();
        assert!(
            error < 4.0 * sigma + 0.01 * sampled,
            "{formula}: mesh volume {}, sampled {sampled} ± {sigma}",
            m.volume()
        );
    }
}
