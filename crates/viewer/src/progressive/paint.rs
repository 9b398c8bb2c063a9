//! What the window paints of a picture in progress: the last completed stage's texture, and
//! over it the rows the stage in progress has drawn so far.

use super::stages::{Stage, texture_index};
use super::textures::StageTexture;

/// A stretch of a stage texture that is drawn: the rectangle in texture pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Done {
    pub texture: usize,
    pub rect: [u32; 4],
}

/// What the app paints: the textures (by index) and, for the stage in progress, the tiles
/// done so far.
#[derive(Debug, Clone, Default)]
pub struct Paint {
    pub layers: Vec<Done>,
}

/// Where a picture's drawing is, as the layers are worked out from it.
pub(super) struct Progress<'a> {
    pub stages: &'a [Stage],
    pub stage: usize,
    pub textures: &'a [StageTexture],
    /// The texture on screen (the last completed stage's).
    pub shown: Option<usize>,
    pub next_tile: u32,
    pub tile: u32,
}

/// The layers to paint, bottom first: the last completed stage's texture below the rows
/// the stage in progress has done (each window pixel is blitted about once: on a software
/// GPU every layer costs its area), then those rows, if that stage draws into a different
/// texture.
pub(super) fn layers(progress: Progress<'_>) -> Paint {
    let Progress {
        stages,
        stage,
        textures,
        shown,
        next_tile,
        tile,
    } = progress;
    let mut layers = Vec::new();
    // The part of the picture's height done by the stage in progress, 0..1.
    let mut covered = 0.0;
    if let Some(stage) = stages.get(stage) {
        let i = texture_index(stage.div);
        if shown != Some(i) && next_tile > 0 {
            let t = &textures[i];
            let cols = t.width.div_ceil(tile);
            let full_rows = next_tile / cols;
            let partial = next_tile % cols;
            let rows_h = (full_rows * tile).min(t.height);
            // The blit filters bilinearly, so a layer stops one texel short of texels not
            // drawn yet (else a dark seam shows along the edge).
            let short = |end: u32, limit: u32| if end > 0 && end < limit { end - 1 } else { end };
            let shown_h = short(rows_h, t.height);
            if shown_h > 0 {
                layers.push(Done {
                    texture: i,
                    rect: [0, 0, t.width, shown_h],
                });
                covered = f64::from(shown_h) / f64::from(t.height);
            }
            let partial_w = (partial * tile).min(t.width);
            let partial_h = tile.min(t.height - rows_h);
            if partial > 0 && rows_h < t.height && partial_w > 1 && partial_h > 1 {
                layers.push(Done {
                    texture: i,
                    rect: [
                        0,
                        shown_h,
                        short(partial_w, t.width),
                        short(rows_h + partial_h, t.height) - shown_h,
                    ],
                });
            }
        }
    }
    if let Some(i) = shown {
        let t = &textures[i];
        let top = ((covered * f64::from(t.height)).floor() as u32).min(t.height);
        if top < t.height {
            layers.insert(
                0,
                Done {
                    texture: i,
                    rect: [0, top, t.width, t.height - top],
                },
            );
        }
    }
    Paint { layers }
}
