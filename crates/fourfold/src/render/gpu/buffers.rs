//! The ray caster's storage buffers: the hierarchy and its bounds (per tree), the tile lists
//! and box records (per view, rewritten in place and grown when too small), the interpreting shader's
//! program (per formula), and the bind group over all eight.

use wgpu::util::DeviceExt;

use crate::gpu_layout::{BoxRecord, NodeBounds, SphereNode};
use crate::render::view::{TileLists, Tiling};
use crate::tree::Hierarchy;

use super::device::{Gpu, GpuError, STORAGE_BUFFERS};

/// The hierarchy's nodes (binding 1) and their slope and curvature bounds (binding 4,
/// unbounded where none).
pub(super) fn node_buffers(
    gpu: &Gpu,
    hierarchy: &Hierarchy,
) -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
    let limit = gpu.device.limits().max_storage_buffer_binding_size;
    // The larger of the two.
    let bytes = (hierarchy.nodes.len() * std::mem::size_of::<NodeBounds>()) as u64;
    if bytes > limit {
        return Err(GpuError::TooLarge {
            nodes: hierarchy.nodes.len(),
            bytes,
            limit,
        });
    }
    // An empty tree still needs non-empty buffers; the shader reads node_count = 0.
    let placeholder = [SphereNode {
        center: [0.0; 4],
        skip: 1,
        meta: 0,
    }];
    let nodes: &[SphereNode] = if hierarchy.nodes.is_empty() {
        &placeholder
    } else {
        &hierarchy.nodes
    };
    let bounds: Vec<NodeBounds> = (0..nodes.len()).map(|i| hierarchy.bounds(i)).collect();
    let buffer = |label: &str, contents: &[u8]| {
        gpu.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
    };
    Ok((
        buffer("fourfold hierarchy", bytemuck::cast_slice(nodes)),
        buffer("fourfold node bounds", bytemuck::cast_slice(&bounds)),
    ))
}

/// A storage buffer for a view's data (tile lists or box records) that `write_or_grow`
/// rewrites: `bytes` long (a binding can't be empty), zeroed.
pub(super) fn view_buffer(gpu: &Gpu, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fourfold view data"),
        size: bytes.max(std::mem::size_of::<BoxRecord>() as u64),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Writes `data` (at most the device's storage-buffer limit) at the start of `buffer`,
/// first replacing it by a larger one (the next power of two, within the limit) if it is
/// too small; returns whether it was replaced (the bind group must then be made anew).
pub(super) fn write_or_grow(gpu: &Gpu, buffer: &mut wgpu::Buffer, data: &[u8]) -> bool {
    let len = data.len() as u64;
    let grow = len > buffer.size();
    if grow {
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        *buffer = view_buffer(gpu, len.next_power_of_two().min(limit));
    }
    gpu.queue.write_buffer(buffer, 0, data);
    grow
}

/// Tile lists that fit the device's storage-buffer limit (and hold anything).
pub(super) fn usable<'a>(gpu: &Gpu, lists: Option<&'a TileLists>) -> Option<&'a TileLists> {
    let limit = gpu.device.limits().max_storage_buffer_binding_size;
    lists.filter(|l| {
        (l.data.len() as u64) * 4 <= limit
            && std::mem::size_of_val(l.boxes.as_slice()) as u64 <= limit
            && !l.data.is_empty()
    })
}

/// `Uniforms::tiling` for bound lists.
pub(super) fn tiling_of(l: &TileLists) -> Tiling {
    Tiling {
        tile: l.tile,
        tiles_per_row: l.tiles_x,
        bound: 1,
        entries_start: l.tiles_x * l.tiles_y + 1,
    }
}

/// Bindings 0 to 7: uniforms, hierarchy, tile lists, box records, node bounds, certifying
/// tile lists and their box records, and the interpreting shader's program.
pub(super) fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: [&wgpu::Buffer; STORAGE_BUFFERS as usize],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .zip(0u32..)
        .map(|(buffer, binding)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fourfold bind group"),
        layout,
        entries: &entries,
    })
}

/// The interpreting shader's program for a formula (binding 7; `shader::program`), or for
/// another shader a placeholder it never reads.
pub(super) fn program_buffer(gpu: &Gpu, program: &[[u32; 4]]) -> wgpu::Buffer {
    let placeholder = [[0u32; 4]];
    let words = if program.is_empty() {
        &placeholder[..]
    } else {
        program
    };
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fourfold interpreted program"),
            contents: bytemuck::cast_slice(words),
            usage: wgpu::BufferUsages::STORAGE,
        })
}
