//! The shader's interval enclosures run on the GPU over given boxes, outside any frame: how
//! the tests check them against F's values (docs/method.md §5.9), as one more [`Evaluator`]
//! of the conformance suite.

use bytemuck::Zeroable;
use wgpu::util::DeviceExt;

use crate::eval::evaluator::check_call;
use crate::eval::{Box4, Evaluator, Tape};
use crate::formula::CompiledFormula;
use crate::interval::Interval;
use crate::render::gpu::{Gpu, GpuError};
use crate::render::shader;
use crate::render::view::Uniforms;

use super::wait::read_back;

/// What the shader encloses over one box: F (`ff_f_box`) and whether it flagged a possible
/// jump, then F and its gradient (`ff_f_grad_box`); each an interval [lo, hi] (lo > hi:
/// empty; ±2^62: unbounded on that side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Enclosures {
    pub f: [f32; 2],
    pub jump: bool,
    pub f_grad: [[f32; 2]; 5],
}

/// The compute entry point appended to the ray caster's shader: one box per invocation,
/// four vec4 out (beside the formula's constants in binding 7).
const PROBE: &str = r#"
@group(0) @binding(8) var<storage, read> probe_boxes: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn cs_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    // (Binding 7 in the layout whichever constants F's enclosures read.)
    _ = arrayLength(&ff_constants);
    if (2u * i + 1u >= arrayLength(&probe_boxes)) {
        return;
    }
    u = settings;
    iv_jump = false;
    let f = ff_f_box(probe_boxes[2u * i], probe_boxes[2u * i + 1u]);
    let jump = select(0.0, 1.0, iv_jump);
    let fg = ff_f_grad_box(probe_boxes[2u * i], probe_boxes[2u * i + 1u]);
    probe_out[4u * i] = vec4<f32>(f, jump, 0.0);
    probe_out[4u * i + 1u] = vec4<f32>(fg.f, fg.gx);
    probe_out[4u * i + 2u] = vec4<f32>(fg.gy, fg.gz);
    probe_out[4u * i + 3u] = vec4<f32>(fg.gw, 0.0, 0.0);
}
"#;

/// Encloses `formula` (with parameter values `params`) over each box [lo, hi] on the GPU.
pub fn enclose(
    gpu: &Gpu,
    formula: &CompiledFormula,
    params: &[f64],
    boxes: &[([f32; 4], [f32; 4])],
) -> Result<Vec<Enclosures>, GpuError> {
    let shader = shader::generate(formula).map_err(|e| GpuError::Pipeline(e.to_string()))?;
    let source = format!("{}\n{PROBE}", shader.source);
    let device = &gpu.device;
    let (pipeline, error) = crate::platform::validated(device, || {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fourfold interval probe"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("fourfold interval probe"),
            layout: None,
            module: &module,
            entry_point: Some("cs_probe"),
            compilation_options: Default::default(),
            cache: None,
        })
    });
    if let Some(error) = error {
        return Err(GpuError::Pipeline(error.to_string()));
    }
    let mut settings = Uniforms::zeroed();
    settings.counts.nan_bits = f32::NAN.to_bits();
    settings.set_params(params);
    let settings = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("fourfold probe settings"),
        contents: bytemuck::bytes_of(&settings),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let flat: Vec<[f32; 4]> = boxes.iter().flat_map(|&(lo, hi)| [lo, hi]).collect();
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("fourfold probe boxes"),
        contents: bytemuck::cast_slice(&flat),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out_bytes = (boxes.len().max(1) * 4 * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fourfold probe out"),
        size: out_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fourfold probe readback"),
        size: out_bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    // (A formula without constants binds a word of zeros: a binding is never empty.)
    let table = if shader.constants.is_empty() {
        vec![[0u32; 4]]
    } else {
        shader.constants.clone()
    };
    let constants = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("fourfold probe constants"),
        contents: bytemuck::cast_slice(&table),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fourfold probe bindings"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: settings.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 7,
                resource: constants.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 8,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 9,
                resource: output.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((boxes.len() as u32).div_ceil(64).max(1), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, out_bytes);
    gpu.queue.submit([encoder.finish()]);
    let values: Vec<[f32; 4]> =
        read_back(gpu, readback, |data| bytemuck::cast_slice(data).to_vec())?;
    Ok(values
        .chunks_exact(4)
        .take(boxes.len())
        .map(|v| {
            let [a, b, c, d] = [v[0], v[1], v[2], v[3]];
            Enclosures {
                f: [a[0], a[1]],
                jump: a[2] != 0.0,
                f_grad: [
                    [b[0], b[1]],
                    [b[2], b[3]],
                    [c[0], c[1]],
                    [c[2], c[3]],
                    [d[0], d[1]],
                ],
            }
        })
        .collect())
}

/// The GPU's enclosures as an [`Evaluator`]: over boxes (rounded outward to f32), the
/// formula's F (`tape_f`, by `ff_f_box`) or F and ∇F (`tape_all`, by `ff_f_grad_box`) as the
/// shader computes them. It runs only those two tapes of the one formula: the shader is
/// generated for the formula, not for any tape.
pub struct GpuEnclosures<'a> {
    gpu: &'a Gpu,
    formula: &'a CompiledFormula,
}

impl<'a> GpuEnclosures<'a> {
    pub fn new(gpu: &'a Gpu, formula: &'a CompiledFormula) -> Self {
        Self { gpu, formula }
    }
}

/// A box's bounds in f32, rounded outward so that the f32 box holds the f64 one.
fn outward(bx: &Box4) -> ([f32; 4], [f32; 4]) {
    let down = |v: f64| {
        let f = v as f32;
        if f64::from(f) > v { f.next_down() } else { f }
    };
    let up = |v: f64| {
        let f = v as f32;
        if f64::from(f) < v { f.next_up() } else { f }
    };
    (bx.map(|i| down(i.lo())), bx.map(|i| up(i.hi())))
}

/// An enclosure from the GPU as an interval: lo > hi is empty, ±2^62 stand for ±∞.
fn interval_of([lo, hi]: [f32; 2]) -> Interval {
    const BIG: f64 = 4_611_686_018_427_387_904.0;
    let (lo, hi) = (f64::from(lo), f64::from(hi));
    if lo > hi || lo.is_nan() || hi.is_nan() {
        return Interval::EMPTY;
    }
    Interval::new(
        if lo <= -BIG { f64::NEG_INFINITY } else { lo },
        if hi >= BIG { f64::INFINITY } else { hi },
    )
}

impl Evaluator for GpuEnclosures<'_> {
    type Input = Box4;
    type Output = Interval;

    fn batch_size(&self) -> usize {
        1 << 16
    }

    fn evaluate(
        &mut self,
        tape: &Tape,
        inputs: &[Box4],
        params: &[f64],
        out: &mut [Interval],
    ) -> Result<(), String> {
        check_call(tape, inputs, out, self.batch_size())?;
        let whole = if tape.id() == self.formula.tape_f.id() {
            false
        } else if tape.id() == self.formula.tape_all.id() {
            true
        } else {
            return Err("the GPU encloses only its formula's F, and F with ∇F".into());
        };
        let boxes: Vec<_> = inputs.iter().map(outward).collect();
        let found = enclose(self.gpu, self.formula, params, &boxes).map_err(|e| e.to_string())?;
        let n = tape.outputs().len();
        for (e, values) in found.iter().zip(out.chunks_mut(n)) {
            if whole {
                for (v, g) in values.iter_mut().zip(e.f_grad) {
                    *v = interval_of(g);
                }
            } else {
                values[0] = interval_of(e.f);
            }
        }
        Ok(())
    }
}
