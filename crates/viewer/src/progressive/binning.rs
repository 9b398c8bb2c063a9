//! The per-tile box lists of each view the picture is drawn in, binned off the window's
//! frames (the binning of a full-size view takes longer than a frame) and handed to the ray
//! caster once done.

use std::sync::Arc;

use web_time::Instant;

use fourfold::render::{Camera, Gpu, RayCaster, TileLists};
use fourfold::tree::Hierarchy;

use crate::platform::Background;

/// Which stage texture and plan (view, settings, picture) a set of tile lists is for.
pub(super) type BinKey = (usize, u64);

/// The ray caster's lists, and the certifying ones where asked for.
type Lists = (TileLists, Option<TileLists>);

/// Lists being binned in the background.
struct Binning {
    key: BinKey,
    lists: Background<Lists>,
    started: Instant,
}

/// The tile lists the ray caster holds, the binning in flight, and how long binning takes.
#[derive(Default)]
pub struct Binner {
    binned: Option<BinKey>,
    binning: Option<Binning>,
    /// Wall time of the last binning, milliseconds.
    pub binning_ms: Option<f64>,
    /// Binnings started.
    pub binnings: u64,
}

impl Binner {
    /// Whether the caster holds the tile lists for `key` (and, for a certified view, the
    /// certifying lists); if not, starts or polls their binning in the background and
    /// uploads them once done.
    pub fn ready(
        &mut self,
        gpu: &Gpu,
        caster: &mut RayCaster,
        (hierarchy, certifying): (&Arc<Hierarchy>, Option<&Arc<Hierarchy>>),
        camera: &Camera,
        key: BinKey,
    ) -> bool {
        if self.binned.as_ref() == Some(&key) {
            return true;
        }
        if let Some(job) = &mut self.binning
            && job.key == key
        {
            let Some(done) = job.lists.poll() else {
                return false;
            };
            // Without lists (the worker died, short of memory), the caster walks the
            // hierarchy, which needs none.
            let (lists, cert) = match done {
                Some((lists, cert)) => (Some(lists), cert),
                None => (None, None),
            };
            self.binning_ms = Some(job.started.elapsed().as_secs_f64() * 1e3);
            caster.set_tiles(gpu, lists.as_ref());
            caster.set_cert_tiles(gpu, cert.as_ref());
            self.binning = None;
            self.binned = Some(key);
            return true;
        }
        // A new view: bin it (a stale job finishes on its own; its result is dropped).
        let (shared, view, budget) = (hierarchy.clone(), *camera, gpu.tile_entry_budget());
        let shared_cert = certifying.cloned();
        self.binnings += 1;
        self.binning = Some(Binning {
            key,
            lists: Background::start("fourfold binning", move || {
                let cert = shared_cert.map(|c| TileLists::build_within(&c, &view, budget));
                (TileLists::build_within(&shared, &view, budget), cert)
            }),
            started: Instant::now(),
        });
        // (Where the work ran at once, the lists are ready now.)
        self.ready(gpu, caster, (hierarchy, certifying), camera, key)
    }
}
