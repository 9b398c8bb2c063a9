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

    /// Draws a new plan's preview on the CPU where its pipeline is not built yet (see
    /// `cpu_preview`), before the stages planned for the GPU, or as the first of them
    /// where it is as fine.
    pub(super) fn preview_on_cpu(
        &mut self,
        gpu: &Gpu,
        caster: &RayCaster,
        picture: (&CompiledFormula, &[f64], &Hierarchy),
        scene: &Scene,
    ) {
        let Some(&planned) = self.stages.first() else {
            return;
        };
        let drawn = crate::job::first_frames(scene, scene.render.brute_force);
        if planned.div == 1 || caster.has_pipeline_for(&drawn, picture.2) {
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
        self.complete_stage(gpu, self.stages[0], false);
        self.preview_from_cpu = true;
    }
}
