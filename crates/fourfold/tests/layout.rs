//! The structs of `src/gpu_layout.rs` against the shader's: sizes and member offsets as
//! naga lays out the generated WGSL.

use std::mem::{offset_of, size_of};

use fourfold::gpu_layout::*;

/// (WGSL member, its offset as Rust lays it out), for each member of a struct.
macro_rules! members {
    ($ty:ty { $($field:ident),* $(,)? }) => {
        vec![$((stringify!($field), offset_of!($ty, $field))),*]
    };
}

/// The shader as fourfold generates it, parsed by naga (which lays out its structs).
fn shader_module() -> naga::Module {
    let formula = fourfold::CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 - R").unwrap();
    fourfold::render::shader::generate(&formula).unwrap().module
}

/// Checks the WGSL struct `name` against a Rust struct of `size` bytes whose members
/// are `rust` (WGSL member name, Rust offset): same size, same members at the same
/// offsets, none left out.
fn check(module: &naga::Module, name: &str, size: usize, rust: Vec<(&str, usize)>) {
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("the shader has no struct {name}"));
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("{name} is not a struct in the shader");
    };
    assert_eq!(*span as usize, size, "{name}: WGSL size against Rust's");
    let wgsl: Vec<(&str, usize)> = members
        .iter()
        .map(|m| (m.name.as_deref().unwrap_or("?"), m.offset as usize))
        .collect();
    assert_eq!(
        wgsl, rust,
        "{name}: WGSL members and offsets against Rust's"
    );
}

#[test]
fn the_buffers_structs_are_laid_out_as_the_shader_reads_them() {
    let module = shader_module();
    check(
        &module,
        "SphereNode",
        size_of::<SphereNode>(),
        vec![
            ("cx", 0),
            ("cy", 4),
            ("cz", 8),
            ("cw", 12),
            ("skip", offset_of!(SphereNode, skip)),
            ("info", offset_of!(SphereNode, meta)),
        ],
    );
    check(
        &module,
        "LevelInfo",
        size_of::<LevelInfo>(),
        members!(LevelInfo { half, radius }),
    );
    check(
        &module,
        "Curvature",
        size_of::<Curvature>(),
        members!(Curvature {
            diag_lo,
            diag_hi,
            off_lo,
            off_hi,
            rest
        }),
    );
    check(
        &module,
        "NodeBounds",
        size_of::<NodeBounds>(),
        members!(NodeBounds { slope, curvature }),
    );
    check(
        &module,
        "PlaneCurvature",
        size_of::<PlaneCurvature>(),
        members!(PlaneCurvature { ab, c }),
    );
    check(
        &module,
        "BoxRecord",
        size_of::<BoxRecord>(),
        members!(BoxRecord {
            view,
            level,
            angles,
            node,
            unused,
            center,
            slope,
            form
        }),
    );
    check(
        &module,
        "Uniforms",
        size_of::<Uniforms>(),
        members!(Uniforms {
            v1,
            v2,
            n1,
            n2,
            center,
            domain_lo,
            domain_hi,
            light,
            surface,
            background,
            silhouette_color,
            border_color,
            shading,
            misc,
            root,
            size,
            control,
            counts,
            tiling,
            half0,
            march,
            hidden,
            cert_tiling,
            levels,
            params
        }),
    );
}

#[test]
fn each_vec4_block_of_the_settings_is_sixteen_bytes() {
    // The shader reads these as vec4<f32> / vec4<u32>: their fields are its x, y, z, w.
    for (name, size) in [
        ("Shading", size_of::<Shading>()),
        ("Misc", size_of::<Misc>()),
        ("Root", size_of::<Root>()),
        ("Size", size_of::<Size>()),
        ("Control", size_of::<Control>()),
        ("Counts", size_of::<Counts>()),
        ("Tiling", size_of::<Tiling>()),
        ("March", size_of::<March>()),
        ("Hidden", size_of::<Hidden>()),
    ] {
        assert_eq!(size, 16, "{name}");
    }
}
