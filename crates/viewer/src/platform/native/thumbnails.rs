//! The gallery's pictures on the desktop: drawn one after another on a thread and a GPU
//! device of their own, so that the window never waits for them.

use super::threads;
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use fourfold::render::{Gpu, Prepared};
use fourfold::scene::EXAMPLES;

use crate::gallery::{Thumbnail, start_thumbnail, thumbnail_job};

/// The gallery's pictures being made, each arriving with its example's index.
pub struct Thumbnails(Receiver<(usize, Thumbnail)>);

impl Thumbnails {
    /// Starts drawing every example's picture (on a device of its own: not the window's).
    pub fn start(_window_gpu: Option<&Gpu>) -> Self {
        let (tx, rx) = channel();
        // (If no thread can start, the sender is dropped: the gallery shows no pictures.)
        let _ = threads::spawn("fourfold gallery", move || {
            let gpu = threads::open_gpu();
            for (i, (name, _)) in EXAMPLES.iter().enumerate() {
                if threads::exiting() {
                    return;
                }
                let picture = match &gpu {
                    Ok(gpu) => thumbnail(gpu, name),
                    Err(e) => Err(e.clone()),
                };
                if tx.send((i, picture)).is_err() {
                    return;
                }
            }
        });
        Self(rx)
    }

    /// The pictures made since the last call, and whether all are made.
    pub fn poll(&mut self, _window_gpu: Option<&Gpu>) -> (Vec<(usize, Thumbnail)>, bool) {
        let mut made = Vec::new();
        loop {
            match self.0.try_recv() {
                Ok(picture) => made.push(picture),
                Err(TryRecvError::Empty) => return (made, false),
                Err(TryRecvError::Disconnected) => return (made, true),
            }
        }
    }
}

/// The example `name`'s gallery picture, drawn and waited for.
fn thumbnail(gpu: &Gpu, name: &str) -> Thumbnail {
    let (scene, formula) = thumbnail_job(name)?;
    let prepared = Prepared::new(&formula, &scene).map_err(|e| e.to_string())?;
    let (_painter, pending) = start_thumbnail(gpu, scene, &formula, &prepared)?;
    Ok(pending.wait().map_err(|e| e.to_string())?.rgba)
}
