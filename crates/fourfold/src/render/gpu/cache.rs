//! Compiled pipelines kept between runs: wgpu's `PipelineCache` where the backend has one
//! (Vulkan), in one file per adapter and shader under the user's cache directory, so that a
//! second run of a formula skips the driver's compile. A file that is broken, cut short or
//! made by another GPU, driver or wgpu is ignored with a warning and written anew; it never
//! stops a picture.
//!
//! A file holds a short header of fourfold's (a magic string, and the CRC-32 and length of
//! the rest, so that bytes damaged on disk never reach the driver), then what `PipelineCache::get_data`
//! gave, which wgpu checks against the adapter and driver when it is loaded.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The start of every cache file.
const MAGIC: &[u8; 16] = b"fourfold-pcache1";
/// Files kept in the directory; the least recently written go first.
const MAX_FILES: usize = 64;

/// Where a device keeps its pipeline caches: a directory, and the adapter's name in them.
#[derive(Debug, Clone)]
pub struct CacheDir {
    dir: PathBuf,
    adapter_key: String,
}

impl CacheDir {
    /// The caches of the adapter described by `info` under `dir`; None where the backend
    /// keeps no pipeline cache (all but Vulkan, in wgpu 30).
    pub fn new(dir: PathBuf, info: &wgpu::AdapterInfo) -> Option<Self> {
        let adapter_key = wgpu::util::pipeline_cache_key(info)?;
        Some(Self { dir, adapter_key })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    fn file_for(&self, shader: &str) -> PathBuf {
        // The shader's checksum and length name it (a clash costs only a compile: the
        // driver finds no pipeline of this shader in the other's cache).
        self.dir.join(format!(
            "{}-{:08x}-{}.bin",
            self.adapter_key,
            crc32fast::hash(shader.as_bytes()),
            shader.len()
        ))
    }
}

/// What became of a ray caster's pipeline cache.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum CacheUse {
    /// No cache: the device has none, or none was asked for.
    #[default]
    Off,
    /// No file yet for this shader and adapter: the pipelines are compiled and saved.
    New,
    /// Loaded from `bytes` bytes on disk: the driver may skip its compile.
    Loaded { bytes: usize },
    /// A file was there but not used (`reason`); the pipelines are compiled and the file
    /// written anew.
    Ignored { file: PathBuf, reason: String },
    /// The file could not be written (`reason`): the next run compiles again.
    Unwritable { file: PathBuf, reason: String },
}

impl CacheUse {
    /// The warning to show the user, if any.
    pub fn warning(&self) -> Option<String> {
        match self {
            CacheUse::Ignored { file, reason } => Some(format!(
                "ignored the pipeline cache {} ({reason}); it is written anew",
                file.display()
            )),
            CacheUse::Unwritable { file, reason } => Some(format!(
                "could not write the pipeline cache {} ({reason}); the next run compiles its \
                 pipelines again (FOURFOLD_CACHE_DIR=off keeps none)",
                file.display()
            )),
            _ => None,
        }
    }
}

/// The pipeline cache of one shader on one device, and the file it is kept in.
pub(super) struct ShaderCache {
    pub(super) cache: wgpu::PipelineCache,
    file: PathBuf,
    /// How many bytes of cache data the file holds now (None: not written by us yet).
    saved: Mutex<Option<usize>>,
}

impl ShaderCache {
    /// The cache for `shader` on `device` from its file in `dir` (a new, empty one where
    /// there is none or it is ignored), and what became of the file.
    pub(super) fn open(device: &wgpu::Device, dir: &CacheDir, shader: &str) -> (Self, CacheUse) {
        let file = dir.file_for(shader);
        let (data, mut state) = match std::fs::read(&file) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => (None, CacheUse::New),
            Err(e) => (None, ignored(&file, format!("unreadable: {e}"))),
            Ok(bytes) => match unwrap_file(&bytes) {
                Ok(data) => (Some(data.to_vec()), CacheUse::Loaded { bytes: data.len() }),
                Err(reason) => (None, ignored(&file, reason.to_string())),
            },
        };
        let create = |data: Option<&[u8]>| {
            crate::platform::validated(device, || create_pipeline_cache(device, data))
        };
        let (mut cache, error) = create(data.as_deref());
        if let Some(error) = error {
            state = ignored(
                &file,
                format!("made for another GPU, driver or wgpu: {error}"),
            );
            cache = create(None).0;
        }
        let saved = match state {
            CacheUse::Loaded { bytes } => Some(bytes),
            _ => None,
        };
        let cache = Self {
            cache,
            file,
            saved: Mutex::new(saved),
        };
        (cache, state)
    }

    /// Writes the cache's data to its file when it has changed since it was loaded or last
    /// written (a pipeline was added). Failing to write only loses the cache: Err says why.
    pub(super) fn save(&self) -> Result<(), CacheUse> {
        let Some(data) = self.cache.get_data() else {
            return Ok(());
        };
        let mut saved = self.saved.lock().unwrap_or_else(|e| e.into_inner());
        if *saved == Some(data.len()) {
            return Ok(());
        }
        write_file(&self.file, &data).map_err(|e| CacheUse::Unwritable {
            file: self.file.clone(),
            reason: e.to_string(),
        })?;
        *saved = Some(data.len());
        if let Some(dir) = self.file.parent() {
            prune(dir);
        }
        Ok(())
    }
}

/// A pipeline cache on `device` holding `data`, or empty.
// One of the workspace's two unsafe calls (the other: the viewer's hook at the process's
// exit): wgpu has no safe way to make a cache from data.
#[allow(unsafe_code)]
fn create_pipeline_cache(device: &wgpu::Device, data: Option<&[u8]>) -> wgpu::PipelineCache {
    // SAFETY: `data` is what `PipelineCache::get_data` gave on an earlier run, written by
    // `write_file` with a checksum that `unwrap_file` verified (so it is those bytes,
    // undamaged); wgpu checks that it was made by this adapter, driver and wgpu version, and
    // reports it as a validation error otherwise (`fallback: false`).
    unsafe {
        device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
            label: Some("fourfold pipelines"),
            data,
            fallback: false,
        })
    }
}

fn ignored(file: &Path, reason: String) -> CacheUse {
    CacheUse::Ignored {
        file: file.to_path_buf(),
        reason,
    }
}

/// The cache data in a file's bytes, once its header and checksum are checked.
fn unwrap_file(bytes: &[u8]) -> Result<&[u8], &'static str> {
    let header = MAGIC.len() + 8;
    if bytes.len() < header || &bytes[..MAGIC.len()] != MAGIC {
        return Err("not a fourfold pipeline cache");
    }
    let sum = u64::from_le_bytes(bytes[MAGIC.len()..header].try_into().expect("8 bytes"));
    let data = &bytes[header..];
    if checksum(data) != sum {
        return Err("damaged: its checksum does not match");
    }
    Ok(data)
}

/// Writes `data` with its header to a file of its own first, then renames it into place, so
/// that a reader (another fourfold at the same time) sees the old file or the new, whole.
fn write_file(file: &Path, data: &[u8]) -> std::io::Result<()> {
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut bytes = Vec::with_capacity(MAGIC.len() + 8 + data.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&checksum(data).to_le_bytes());
    bytes.extend_from_slice(data);
    // A name of this write's own: other threads and processes may write the same cache.
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let write = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let temp = file.with_extension(format!("{}-{write}.tmp", std::process::id()));
    std::fs::write(&temp, &bytes)?;
    std::fs::rename(&temp, file).inspect_err(|_| {
        let _ = std::fs::remove_file(&temp);
    })
}

/// Removes the least recently written cache files beyond MAX_FILES.
fn prune(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut files: Vec<(std::time::SystemTime, PathBuf)> = entries
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "bin"))
        .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
        .collect();
    if files.len() <= MAX_FILES {
        return;
    }
    files.sort();
    for (_, path) in &files[..files.len() - MAX_FILES] {
        let _ = std::fs::remove_file(path);
    }
}

/// The data's CRC-32 and its length: a file damaged or cut short fails it.
fn checksum(data: &[u8]) -> u64 {
    u64::from(crc32fast::hash(data)) | (data.len() as u64) << 32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_read_back_only_whole_and_undamaged() {
        let dir = std::env::temp_dir().join(format!("fourfold-cache-unit-{}", std::process::id()));
        let file = dir.join("a.bin");
        write_file(&file, b"pipelines").unwrap();
        let bytes = std::fs::read(&file).unwrap();
        assert_eq!(unwrap_file(&bytes), Ok(&b"pipelines"[..]));
        let mut damaged = bytes.clone();
        *damaged.last_mut().unwrap() ^= 1;
        assert_eq!(
            unwrap_file(&damaged),
            Err("damaged: its checksum does not match")
        );
        assert_eq!(
            unwrap_file(&bytes[..bytes.len() - 1]),
            Err("damaged: its checksum does not match")
        );
        assert_eq!(unwrap_file(b"{}"), Err("not a fourfold pipeline cache"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn only_the_newest_files_are_kept() {
        let dir = std::env::temp_dir().join(format!("fourfold-cache-prune-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for k in 0..MAX_FILES + 3 {
            std::fs::write(dir.join(format!("{k}.bin")), b"x").unwrap();
        }
        std::fs::write(dir.join("other.txt"), b"x").unwrap();
        prune(&dir);
        let left = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(left, MAX_FILES + 1);
        assert!(dir.join("other.txt").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
