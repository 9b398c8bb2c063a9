//! The progressive picture's side of a preview drawn on the CPU (`cpu_preview`): where it
//! goes among the stages, and the GPU's wait after it.

use web_time::Instant;

use fourfold::CompiledFormula;
use fourfold::render::{Gpu, RayCaster};
use fourfold::scene::Scene;
use fourfold::tree::Hierarchy;

use super::super::stages::{Stage, texture_index};
use super::Progressive;

impl Progressive {
    /// Whether the GPU's stages wait after a preview on the CPU, which is on screen at this
    /// frame before a pipeline compiles; the window sleeps until the hold is over.
    pub(super) fn held_after_cpu_preview(&mut self) -> bool {
        let Some(left) = self.cpu_previews.gpu_held() else {
            return false;
        };
        self.waiting = true;
        if let Some(ctx) = &self.wake {
            ctx.request_repaint_after(left);
        }
        true
    }

    /// Draws a new plan's preview on the CPU (see `cpu_preview`) where its pipeline is not
    /// built yet, or for a `new_picture` (a new formula or tree: the GPU's first stage,
    /// planned for the last picture's speed, took 0.2-1.8 s on SwiftShader where the twin
    /// takes 10-40 ms), before the stages planned for the GPU, or as the first of them
    /// where it is as fine. The GPU's stages wait after it only where their pipeline would
    /// compile.
    pub(super) fn preview_on_cpu(
        &mut self,
        gpu: &Gpu,
        caster: &RayCaster,
        picture: (&CompiledFormula, &[f64], &Hierarchy),
        scene: &Scene,
        new_picture: bool,
    ) {
        let Some(&planned) = self.stages.first() else {
            return;
        };
        let drawn = crate::job::first_frames(scene, scene.render.brute_force);
        let built = caster.has_pipeline_for(&drawn, picture.2);
        if planned.div == 1 || (built && !new_picture) {
            return;
        }
        let previews = &mut self.cpu_previews;
        let instructions = picture.0.tape_all.len();
        let Some(div) = previews.divisor(self.size, planned.rays, instructions, planned.div) else {
            return;
        };
        if div != planned.div {
            self.stages.insert(0, Stage { div, ..planned });
        }
        self.stage_started = Some(Instant::now());
        let texture = &self.textures[texture_index(div)];
        previews.draw(gpu, (texture, div), picture, &drawn, planned.rays);
        previews.hold_gpu(!built);
        self.complete_stage(gpu, self.stages[0], false);
        self.preview_from_cpu = true;
    }
}
