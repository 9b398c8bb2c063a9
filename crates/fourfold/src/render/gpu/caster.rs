//! The ray caster: a pipeline per variant of one shader (one formula), the hierarchy in a
//! storage buffer (per tree), the tile lists of one view, and the frame's settings
//! (`Uniforms`) in a small read-only storage buffer rather than a uniform buffer (lavapipe
//! rebuilds a shader whose loops a uniform buffer steers at every write: docs/architecture.md,
//! "The GPU"). It draws into a texture of the caller's, or offscreen for read-back.

use std::sync::Arc;

use bytemuck::Zeroable;

use crate::render::shader::Shader;
use crate::render::view::{Camera, FLAG_KEEP_MISSES, TileLists, Tiling, Uniforms};
use crate::scene::Scene;
use crate::tree::Hierarchy;

use super::buffers::{
    bind_group, node_buffers, program_buffer, tiling_of, usable, view_buffer, write_or_grow,
};
use super::cache::{CacheUse, ShaderCache};
use super::device::{Gpu, GpuError, STORAGE_BUFFERS, check_image_size};
use super::pipelines::{
    Fullscreen, Mode, Pass, Target, Variant, build_pipeline, color_target, fullscreen_pipeline,
    storage_entry,
};
use super::readback::{FrameCopy, PendingRgba, Timer};

/// What the casters of one shader share (`RayCaster::sibling`): the target they draw into,
/// the shader module and layouts, and where the pipelines are kept between runs
/// (`Gpu::pipeline_cache`) with what became of the file when the first was built.
#[derive(Clone)]
pub(super) struct Shared {
    target: Target,
    pub(super) module: wgpu::ShaderModule,
    pub(super) pipeline_layout: wgpu::PipelineLayout,
    layout: wgpu::BindGroupLayout,
    cache: Option<Arc<ShaderCache>>,
    cache_use: CacheUse,
    /// The shader is the interpreting one (`Shader::interprets`): plain pixels only.
    pub(super) interprets: bool,
    /// Its source's hash (`source_hash`): which formulas' shaders it draws.
    pub(super) source_hash: u64,
}

/// A shader source's hash, within one run.
pub(super) fn source_hash(source: &str) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    source.hash(&mut hasher);
    hasher.finish()
}

/// A compiled pipeline for one shader, and the buffers for one hierarchy.
pub struct RayCaster {
    pub(super) shared: Shared,
    /// Per [`Variant`] (`Variant::index`); the tile pipeline for the default settings is
    /// built at once, the others when first used.
    pub(super) pipelines: [std::sync::OnceLock<wgpu::RenderPipeline>; Variant::COUNT],
    uniforms: wgpu::Buffer,
    nodes: wgpu::Buffer,
    /// Per node, `Hierarchy::slope` and `Hierarchy::curvature` (read by the walk and,
    /// through their records, the tiles).
    bounds: wgpu::Buffer,
    tiles: wgpu::Buffer,
    /// The records of the boxes the tile lists index.
    boxes: wgpu::Buffer,
    /// `Uniforms::tiling` for the tile lists bound (zero: walk the hierarchy).
    tiling: Tiling,
    /// The certifying tile lists and their box records (certified pixels), and their
    /// `Uniforms::cert_tiling` (zero: none bound).
    cert_tiles: wgpu::Buffer,
    cert_boxes: wgpu::Buffer,
    cert_tiling: Tiling,
    /// Binding 7: the interpreting shader's program, or the formula's constants for its own
    /// shader (`Shader::constants`), and the words it holds.
    pub(super) program: wgpu::Buffer,
    pub(super) words: Vec<[u32; 4]>,
    bind_group: wgpu::BindGroup,
    /// Where the tile lists have boxes to march (`TileLists::rects`); a pass draws the
    /// background elsewhere.
    rects: Vec<[u32; 4]>,
    /// Draws the background (built when first used).
    pub(super) background: std::sync::OnceLock<wgpu::RenderPipeline>,
}

impl RayCaster {
    /// Builds the pipeline for `shader` (already validated by naga) and uploads `hierarchy`,
    /// for offscreen RGBA8 pictures.
    pub fn new(gpu: &Gpu, shader: &Shader, hierarchy: &Hierarchy) -> Result<Self, GpuError> {
        Self::with_target(gpu, shader, hierarchy, Target::OFFSCREEN)
    }

    /// As [`RayCaster::new`], drawing into `target`.
    pub fn with_target(
        gpu: &Gpu,
        shader: &Shader,
        hierarchy: &Hierarchy,
        target: Target,
    ) -> Result<Self, GpuError> {
        Self::with_first(gpu, shader, hierarchy, target, Some(Variant::first()))
    }

    /// As [`RayCaster::with_target`], building now the one pipeline that frames of `scene`
    /// draw with (a slice's, a slab's, a certified one...), and no other: a pipeline built
    /// inside a frame costs that frame the pipeline's compile (hundreds of milliseconds on
    /// llvmpipe), and one that no frame uses costs it for nothing.
    pub fn for_scene(
        gpu: &Gpu,
        shader: &Shader,
        hierarchy: &Hierarchy,
        target: Target,
        scene: &Scene,
    ) -> Result<Self, GpuError> {
        Self::with_first(
            gpu,
            shader,
            hierarchy,
            target,
            Some(Variant::of_scene(scene, hierarchy)),
        )
    }

    /// As [`RayCaster::with_target`], building no pipeline yet: each is built when a frame
    /// first draws with it. A web page's choice, where a pipeline compiles in the browser's
    /// GPU process ahead of every frame queued after it: the window shows a preview drawn
    /// on the CPU first.
    pub fn without_pipelines(
        gpu: &Gpu,
        shader: &Shader,
        hierarchy: &Hierarchy,
        target: Target,
    ) -> Result<Self, GpuError> {
        Self::with_first(gpu, shader, hierarchy, target, None)
    }

    /// Whether the pipeline that frames of `scene` draw with is built.
    pub fn has_pipeline_for(&self, scene: &Scene, hierarchy: &Hierarchy) -> bool {
        self.pipelines[Variant::of_scene(scene, hierarchy).index()]
            .get()
            .is_some()
    }

    /// Builds the pipeline that frames of `scene` draw with, if it is not built (on any
    /// thread: the interpreting shader's caster gains a mode's pipeline while others draw).
    pub fn build_pipeline_for(&self, gpu: &Gpu, scene: &Scene, hierarchy: &Hierarchy) {
        self.pipeline(gpu, Variant::of_scene(scene, hierarchy));
    }

    /// What became of the pipeline cache kept between runs when the first pipeline was
    /// built (loaded, new, ignored with a reason, or off).
    pub fn pipeline_cache(&self) -> &CacheUse {
        &self.shared.cache_use
    }

    /// How many ray-caster pipelines are built.
    pub fn pipelines_built(&self) -> usize {
        self.pipelines.iter().filter(|p| p.get().is_some()).count()
    }

    fn with_first(
        gpu: &Gpu,
        shader: &Shader,
        hierarchy: &Hierarchy,
        target: Target,
        first: Option<Variant>,
    ) -> Result<Self, GpuError> {
        let device = &gpu.device;
        let (cache, cache_use) = match &gpu.pipeline_cache {
            Some(dir) => {
                let (cache, found) = ShaderCache::open(device, dir, &shader.source);
                (Some(cache), found)
            }
            None => (None, CacheUse::Off),
        };
        let ((module, layout, pipeline_layout, pipeline), error) =
            crate::platform::validated(device, || {
                let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("fourfold ray caster"),
                    source: crate::platform::shader_source(&shader.source, &shader.module),
                });
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("fourfold bindings"),
                    entries: &(0..STORAGE_BUFFERS).map(storage_entry).collect::<Vec<_>>(),
                });
                let pipeline_layout =
                    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some("fourfold pipeline layout"),
                        bind_group_layouts: &[Some(&layout)],
                        immediate_size: 0,
                    });
                let cached = cache.as_ref().map(|c| &c.cache);
                let pipeline = first.map(|variant| {
                    let pipeline =
                        build_pipeline(device, &module, &pipeline_layout, target, variant, cached);
                    (variant, pipeline)
                });
                (module, layout, pipeline_layout, pipeline)
            });
        if let Some(error) = error {
            return Err(GpuError::Pipeline(error.to_string()));
        }
        let cache_use = match cache.as_ref().map(ShaderCache::save) {
            Some(Err(unwritten)) => unwritten,
            _ => cache_use,
        };
        let pipelines: [std::sync::OnceLock<wgpu::RenderPipeline>; Variant::COUNT] =
            std::array::from_fn(|_| std::sync::OnceLock::new());
        if let Some((variant, pipeline)) = pipeline {
            let _ = pipelines[variant.index()].set(pipeline);
        }
        let shared = Shared {
            target,
            module,
            pipeline_layout,
            layout,
            cache: cache.map(Arc::new),
            cache_use,
            interprets: shader.interprets,
            source_hash: source_hash(&shader.source),
        };
        Self::assemble(gpu, shared, pipelines, hierarchy, shader.constants.clone())
    }

    /// A caster of `shared`'s shader with `pipelines` built, its buffers made for
    /// `hierarchy` and binding 7's `words` (the interpreting shader's program, or the
    /// formula's constants).
    pub(super) fn assemble(
        gpu: &Gpu,
        shared: Shared,
        pipelines: [std::sync::OnceLock<wgpu::RenderPipeline>; Variant::COUNT],
        hierarchy: &Hierarchy,
        words: Vec<[u32; 4]>,
    ) -> Result<Self, GpuError> {
        let device = &gpu.device;
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fourfold uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (nodes, bounds) = node_buffers(gpu, hierarchy)?;
        let tiles = view_buffer(gpu, 0);
        let boxes = view_buffer(gpu, 0);
        let cert_tiles = view_buffer(gpu, 0);
        let cert_boxes = view_buffer(gpu, 0);
        let program = program_buffer(gpu, &words);
        let bind_group = bind_group(
            device,
            &shared.layout,
            [
                &uniforms,
                &nodes,
                &tiles,
                &boxes,
                &bounds,
                &cert_tiles,
                &cert_boxes,
                &program,
            ],
        );
        Ok(Self {
            shared,
            pipelines,
            uniforms,
            nodes,
            bounds,
            tiles,
            boxes,
            tiling: Tiling::zeroed(),
            cert_tiles,
            cert_boxes,
            cert_tiling: Tiling::zeroed(),
            program,
            words,
            bind_group,
            rects: Default::default(),
            background: Default::default(),
        })
    }

    /// Replaces the hierarchy (a new tree for the same formula: parameters, domain, levels).
    pub fn set_hierarchy(&mut self, gpu: &Gpu, hierarchy: &Hierarchy) -> Result<(), GpuError> {
        (self.nodes, self.bounds) = node_buffers(gpu, hierarchy)?;
        self.rebind(gpu);
        // Old tile lists index the old hierarchy.
        self.set_tiles(gpu, None);
        self.set_cert_tiles(gpu, None);
        Ok(())
    }

    /// Binds per-tile box lists and box records for one view (or none: each pixel walks the hierarchy).
    /// Lists over the device's storage-buffer limit are dropped for the walk. The buffers
    /// are rewritten in place (a new view costs no allocation) and grow when too small;
    /// a pass already submitted keeps what it read.
    pub fn set_tiles(&mut self, gpu: &Gpu, lists: Option<&TileLists>) {
        let Some(l) = usable(gpu, lists) else {
            // The walk reads neither buffer, and draws the whole target.
            self.tiling = Tiling::zeroed();
            return;
        };
        self.tiling = tiling_of(l);
        self.rects = l.rects();
        let grew_tiles = write_or_grow(gpu, &mut self.tiles, bytemuck::cast_slice(&l.data));
        let grew_boxes = write_or_grow(gpu, &mut self.boxes, bytemuck::cast_slice(&l.boxes));
        if grew_tiles || grew_boxes {
            self.rebind(gpu);
        }
    }

    /// Binds the certifying lists of one view: the tile lists of
    /// `Prepared::certifying`'s boxes, which certified pixels search (or none: they search
    /// the marched boxes instead). As [`RayCaster::set_tiles`].
    pub fn set_cert_tiles(&mut self, gpu: &Gpu, lists: Option<&TileLists>) {
        let Some(l) = usable(gpu, lists) else {
            self.cert_tiling = Tiling::zeroed();
            return;
        };
        self.cert_tiling = tiling_of(l);
        let grew_tiles = write_or_grow(gpu, &mut self.cert_tiles, bytemuck::cast_slice(&l.data));
        let grew_boxes = write_or_grow(gpu, &mut self.cert_boxes, bytemuck::cast_slice(&l.boxes));
        if grew_tiles || grew_boxes {
            self.rebind(gpu);
        }
    }

    /// Makes the bind group anew for the buffers held now (after any of them is replaced).
    pub(super) fn rebind(&mut self, gpu: &Gpu) {
        self.bind_group = bind_group(
            &gpu.device,
            &self.shared.layout,
            [
                &self.uniforms,
                &self.nodes,
                &self.tiles,
                &self.boxes,
                &self.bounds,
                &self.cert_tiles,
                &self.cert_boxes,
                &self.program,
            ],
        );
    }

    /// Whether tile lists are bound.
    pub fn tiled(&self) -> bool {
        self.tiling.bound != 0
    }

    /// Records one pass: the whole target, or only `pass.region` (the rest is kept), blended
    /// with `pass.weight` when the target accumulates. The uniforms are written to the queue,
    /// so one submission should hold one set of uniforms.
    pub fn encode_pass(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        uniforms: &Uniforms,
        pass: Pass,
    ) {
        self.record_pass(gpu, encoder, target, uniforms, pass, None);
    }

    /// As [`RayCaster::encode_pass`], writing GPU timestamps at the pass's start and end
    /// into queries 0 and 1 of `timestamps`, if given.
    fn record_pass(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        uniforms: &Uniforms,
        pass: Pass,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        if self.shared.interprets && uniforms.certified() {
            // The interpreting shader has no certified pixels, and a plain pass would read
            // as every pixel proved empty: callers wait for the formula's own shader.
            debug_assert!(false, "a certified pass asked of the interpreting shader");
            return;
        }
        let mut uniforms = *uniforms;
        uniforms.tiling = self.tiling;
        uniforms.cert_tiling = self.cert_tiling;
        // A pass that overwrites has nothing to keep where it finds no hit.
        let overwrite = !self.shared.target.accumulate || pass.weight >= 1.0;
        if overwrite {
            uniforms.control.flags &= !FLAG_KEEP_MISSES;
        }
        gpu.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let mode = if uniforms.brute_force() {
            Mode::BruteForce
        } else if self.tiled() {
            Mode::Tiles
        } else {
            Mode::Walk
        };
        // With tile lists, the ray caster runs only where they have boxes to march; the
        // background goes elsewhere where the pass overwrites (a pass blended into the
        // running mean of passes of the same view finds it there already, and blending it
        // with itself keeps it).
        let whole = pass.region.is_none() && !self.shared.target.accumulate;
        let load = if !whole {
            wgpu::LoadOp::Load
        } else if mode == Mode::Tiles {
            let [r, g, b, _] = uniforms.background.map(f64::from);
            wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 })
        } else {
            wgpu::LoadOp::Clear(wgpu::Color::BLACK)
        };
        let mut rpass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("fourfold frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps.map(|query_set| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            }),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let ray_caster = self.pipeline(gpu, Variant::of(mode, &uniforms));
        rpass.set_pipeline(ray_caster);
        rpass.set_bind_group(0, &self.bind_group, &[]);
        let (width, height) = (uniforms.size.width, uniforms.size.height);
        if self.shared.target.accumulate {
            let c = pass.weight.clamp(0.0, 1.0);
            rpass.set_blend_constant(wgpu::Color {
                r: c,
                g: c,
                b: c,
                a: c,
            });
        }
        // The pixels to draw, as a rectangle (x0, y0, x1, y1).
        let region = pass.region.map_or([0, 0, width, height], |[x, y, w, h]| {
            [x, y, x.saturating_add(w), y.saturating_add(h)]
        });
        // One triangle over the target, drawn within scissor rectangles: the region, or
        // with tile lists its parts in `rects` (a SIMD rasterizer runs the ray caster's
        // loop bodies once for a group of pixels even where none of them enters a loop).
        let draw = |rpass: &mut wgpu::RenderPass<'_>, rect: [u32; 4]| {
            let x0 = rect[0].max(region[0]).min(width);
            let y0 = rect[1].max(region[1]).min(height);
            let x1 = rect[2].min(region[2]).min(width);
            let y1 = rect[3].min(region[3]).min(height);
            if x0 < x1 && y0 < y1 {
                rpass.set_scissor_rect(x0, y0, x1 - x0, y1 - y0);
                rpass.draw(0..3, 0..1);
            }
        };
        if mode != Mode::Tiles {
            draw(&mut rpass, region);
            return;
        }
        if overwrite && !whole {
            rpass.set_pipeline(self.background_pipeline(gpu));
            draw(&mut rpass, region);
            rpass.set_pipeline(ray_caster);
        }
        for &rect in &self.rects {
            draw(&mut rpass, rect);
        }
    }

    /// The pipeline of `fs_background`, built on first use.
    fn background_pipeline(&self, gpu: &Gpu) -> &wgpu::RenderPipeline {
        self.background.get_or_init(|| {
            let pipeline = Fullscreen {
                label: "fourfold background",
                module: &self.shared.module,
                layout: &self.shared.pipeline_layout,
                target: color_target(self.shared.target),
                fragment: "fs_background",
                cache: self.kept(),
            };
            self.saved(fullscreen_pipeline(&gpu.device, pipeline, &[]))
        })
    }

    /// The pipeline of `variant`, built on first use (the shader module was validated when
    /// the first pipeline was built, so the others build too).
    fn pipeline(&self, gpu: &Gpu, variant: Variant) -> &wgpu::RenderPipeline {
        self.pipelines[variant.index()].get_or_init(|| {
            self.saved(build_pipeline(
                &gpu.device,
                &self.shared.module,
                &self.shared.pipeline_layout,
                self.shared.target,
                variant,
                self.kept(),
            ))
        })
    }

    /// The pipeline cache kept between runs, if any.
    fn kept(&self) -> Option<&wgpu::PipelineCache> {
        self.shared.cache.as_ref().map(|c| &c.cache)
    }

    /// `pipeline`, once the cache that now holds it is written (a failure to write was
    /// reported when the first pipeline was built).
    fn saved(&self, pipeline: wgpu::RenderPipeline) -> wgpu::RenderPipeline {
        if let Some(cache) = &self.shared.cache {
            let _ = cache.save();
        }
        pipeline
    }

    /// A `width`×`height` texture in this caster's target format.
    pub fn target_texture(
        &self,
        gpu: &Gpu,
        width: u32,
        height: u32,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fourfold target"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.shared.target.format,
            usage,
            view_formats: &[],
        })
    }

    /// Renders one frame offscreen and starts reading it back without waiting (a web page
    /// cannot wait for the GPU): poll the result until it is there. `timed` asks for the
    /// GPU's time for the pass too, where the device has timestamps
    /// ([`Gpu::has_timestamps`]): it excludes the upload, the read-back and the CPU's work.
    pub fn start_rgba(
        &self,
        gpu: &Gpu,
        uniforms: &Uniforms,
        timed: bool,
    ) -> Result<PendingRgba, GpuError> {
        let (width, height) = (uniforms.size.width, uniforms.size.height);
        check_image_size(width, height, &gpu.device.limits())?;
        let texture = self.target_texture(
            gpu,
            width,
            height,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let timer = (timed && gpu.has_timestamps()).then(|| Timer::new(gpu));
        let queries = timer.as_ref().map(|t| &t.queries);
        self.record_pass(gpu, &mut encoder, &view, uniforms, Pass::default(), queries);
        let stamps = timer.map(|t| t.resolve(&mut encoder));
        let copy = FrameCopy::record(gpu, &mut encoder, &texture);
        gpu.queue.submit([encoder.finish()]);
        Ok(PendingRgba::map(copy, stamps))
    }

    /// Gives this caster the tile lists of `camera`'s whole view, for one offscreen frame
    /// drawn with `uniforms` (brute force reads none), and for a certified frame the lists
    /// of `certifying` (`Prepared::certifying`; without it, certified pixels search the
    /// marched boxes).
    pub fn bin_view(
        &mut self,
        gpu: &Gpu,
        hierarchy: &Hierarchy,
        certifying: Option<&Hierarchy>,
        camera: &Camera,
        uniforms: &Uniforms,
    ) {
        if !uniforms.brute_force() {
            let budget = gpu.tile_entry_budget();
            let lists = TileLists::build_within(hierarchy, camera, budget);
            self.set_tiles(gpu, Some(&lists));
            let certifying = certifying.filter(|_| uniforms.certified());
            let lists = certifying.map(|c| TileLists::build_within(c, camera, budget));
            self.set_cert_tiles(gpu, lists.as_ref());
        }
    }
}
