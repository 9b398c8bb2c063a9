//! The gallery's pictures in the page: a page has one thread, so each example's tree is
//! built in slices of the window's frames and its picture drawn on the window's device and
//! read back over the next frames, one example after another.

use std::sync::Arc;

use web_time::Duration;

use fourfold::CompiledFormula;
use fourfold::render::{Gpu, Painter, PendingPicture, PrepareSteps, Prepared};
use fourfold::scene::{EXAMPLES, Scene};

use crate::gallery::{Thumbnail, start_thumbnail, thumbnail_job};

/// How long a frame may build a gallery picture's tree.
const BUILD_SLICE: Duration = Duration::from_millis(8);

/// Where the picture being made is.
enum Stage {
    Building(Box<(PrepareSteps, Scene, Arc<CompiledFormula>)>),
    /// The painter is kept until its picture is back.
    Drawing(Box<(Painter, PendingPicture)>),
}

/// The gallery's pictures being made, one example at a time.
pub struct Thumbnails {
    /// The example being made (all are made once it reaches `EXAMPLES.len()`).
    next: usize,
    stage: Option<Stage>,
}

impl Thumbnails {
    pub fn start(_gpu: Option<&Gpu>) -> Self {
        Self {
            next: 0,
            stage: None,
        }
    }

    /// Works on the picture being made for a slice of this frame; the pictures made, and
    /// whether all are made.
    pub fn poll(&mut self, gpu: Option<&Gpu>) -> (Vec<(usize, Thumbnail)>, bool) {
        let Some(gpu) = gpu else {
            let all = (self.next..EXAMPLES.len()).map(|i| (i, Err("no GPU".to_string())));
            self.next = EXAMPLES.len();
            return (all.collect(), true);
        };
        let mut made = Vec::new();
        if self.next < EXAMPLES.len()
            && let Some(picture) = self.step(gpu)
        {
            made.push((self.next, picture));
            self.next += 1;
        }
        (made, self.next >= EXAMPLES.len())
    }

    /// One step of the example `self.next`: its picture once made (or why it was not).
    fn step(&mut self, gpu: &Gpu) -> Option<Thumbnail> {
        let stage = match self.stage.take() {
            Some(stage) => stage,
            None => match begin(EXAMPLES[self.next].0) {
                Ok(stage) => stage,
                Err(e) => return Some(Err(e)),
            },
        };
        match stage {
            Stage::Building(mut building) => {
                match building.0.step(&building.2, BUILD_SLICE) {
                    Ok(None) => self.stage = Some(Stage::Building(building)),
                    Ok(Some(prepared)) => {
                        let (_, scene, formula) = *building;
                        match start_thumbnail(gpu, scene, &formula, &prepared) {
                            Ok(drawing) => self.stage = Some(Stage::Drawing(Box::new(drawing))),
                            Err(e) => return Some(Err(e)),
                        }
                    }
                    Err(e) => return Some(Err(e.to_string())),
                }
                None
            }
            Stage::Drawing(mut drawing) => match drawing.1.poll() {
                None => {
                    self.stage = Some(Stage::Drawing(drawing));
                    None
                }
                Some(picture) => Some(picture.map(|p| p.rgba).map_err(|e| e.to_string())),
            },
        }
    }
}

/// The first stage of the example `name`'s picture: its tree to build.
fn begin(name: &str) -> Result<Stage, String> {
    let (scene, formula) = thumbnail_job(name)?;
    let steps = Prepared::steps(&formula, &scene, scene.tree.into()).map_err(|e| e.to_string())?;
    Ok(Stage::Building(Box::new((steps, scene, formula))))
}
