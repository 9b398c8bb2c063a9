//! Compiled pipelines kept between runs (`render::gpu::CacheUse`): a second device finds the
//! first's file and draws the same picture; a broken, damaged, foreign or unwritable file
//! is ignored with a warning and never stops a picture. Skipped, with a note, on a device
//! without wgpu's pipeline cache (all but Vulkan).

use std::path::{Path, PathBuf};

use fourfold::CompiledFormula;
use fourfold::headless::render_prepared;
use fourfold::render::gpu::CacheUse;
use fourfold::render::{Device, Gpu, Picture, Prepared};
use fourfold::scene::Scene;

/// A fresh directory for one test's caches.
fn cache_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fourfold-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A slice of the glome drawn on a device of its own that keeps its pipelines in `dir`; None
/// where the device cannot.
fn draw(dir: &Path) -> Option<Picture> {
    let gpu = Gpu::with_cache_dir(Some(dir.to_path_buf())).expect("GPU tests need an adapter");
    if gpu.pipeline_cache.is_none() {
        eprintln!("skipped: {} keeps no pipeline cache", gpu.adapter);
        return None;
    }
    let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 = 1");
    scene.view.slice = Some(0.3);
    scene.tree.max_level = 4;
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let prepared = Prepared::new(&formula, &scene).unwrap();
    let picture = render_prepared(
        &scene,
        &formula,
        &prepared,
        48,
        32,
        Device::Gpu(&gpu),
        Default::default(),
    )
    .unwrap();
    Some(picture)
}

/// The one cache file in `dir`.
fn the_file(dir: &Path) -> PathBuf {
    let files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    files[0].clone()
}

fn reason(cache: &CacheUse) -> String {
    match cache {
        CacheUse::Ignored { reason, .. } => reason.clone(),
        other => panic!("expected the file to be ignored, got {other:?}"),
    }
}

#[test]
fn compiled_pipelines_are_kept_between_runs_and_draw_the_same_picture() {
    let dir = cache_dir("pcache-kept");
    let Some(first) = draw(&dir) else { return };
    assert_eq!(first.times.pipeline_cache, CacheUse::New);
    let file = the_file(&dir);
    let second = draw(&dir).unwrap();
    assert!(
        matches!(second.times.pipeline_cache, CacheUse::Loaded { bytes } if bytes > 0),
        "{:?}",
        second.times.pipeline_cache
    );
    assert_eq!(second.times.pipeline_cache.warning(), None);
    assert_eq!(first.rgba, second.rgba);
    assert_eq!(the_file(&dir), file);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_broken_or_foreign_cache_file_is_ignored_with_a_warning() {
    let dir = cache_dir("pcache-broken");
    let Some(first) = draw(&dir) else { return };
    let file = the_file(&dir);
    let good = std::fs::read(&file).unwrap();
    // Fourfold's header: 16 bytes of magic, the data's CRC-32 and length; then wgpu's data.
    let header = 24;
    let rewrapped = |data: &[u8]| {
        let sum = u64::from(crc32fast::hash(data)) | (data.len() as u64) << 32;
        [&good[..16], &sum.to_le_bytes()[..], data].concat()
    };
    let mut damaged = good.clone();
    *damaged.last_mut().unwrap() ^= 0x40;
    // wgpu's header: 8 bytes of magic, its version and ABI (4 bytes each), then the
    // backend: made "by another backend", checksummed as a whole file of ours.
    let mut foreign_data = good[header..].to_vec();
    foreign_data[16] ^= 0x07;
    let cases = [
        (
            "garbage",
            b"{\"not\": \"a cache\"}".to_vec(),
            "not a fourfold pipeline cache",
        ),
        ("empty", Vec::new(), "not a fourfold pipeline cache"),
        ("damaged", damaged, "checksum does not match"),
        (
            "cut short",
            good[..good.len() - 3].to_vec(),
            "checksum does not match",
        ),
        (
            "foreign",
            rewrapped(&foreign_data),
            "made for another GPU, driver or wgpu",
        ),
    ];
    for (name, bytes, expected) in cases {
        std::fs::write(&file, &bytes).unwrap();
        let picture = draw(&dir).unwrap();
        let cache = &picture.times.pipeline_cache;
        assert!(reason(cache).contains(expected), "{name}: {cache:?}");
        let warning = cache.warning().unwrap();
        assert!(warning.contains("ignored the pipeline cache"), "{warning}");
        assert!(warning.contains(&*file.to_string_lossy()), "{warning}");
        assert_eq!(picture.rgba, first.rgba, "{name}: the picture changed");
        // Written anew: the next run loads it.
        let next = draw(&dir).unwrap();
        assert!(
            matches!(next.times.pipeline_cache, CacheUse::Loaded { .. }),
            "{name}: then {:?}",
            next.times.pipeline_cache
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unwritable_cache_directory_is_reported_and_the_picture_drawn() {
    let dir = cache_dir("pcache-unwritable");
    // A file where the directory should be.
    std::fs::write(&dir, b"in the way").unwrap();
    let Some(picture) = draw(&dir) else {
        std::fs::remove_file(&dir).unwrap();
        return;
    };
    let warning = picture.times.pipeline_cache.warning().unwrap();
    assert!(
        warning.starts_with("could not write the pipeline cache"),
        "{warning}"
    );
    assert!(picture.rgba.chunks(4).any(|p| p[..3] != picture.rgba[..3]));
    std::fs::remove_file(&dir).unwrap();
}
