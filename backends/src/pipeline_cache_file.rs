//! A driver's pipeline cache kept in a file between runs (Vulkan's `VkPipelineCache`,
//! through wgpu's `PipelineCache` or ash directly), so that a driver without a shader
//! cache of its own does not compile every kernel again at each start.
//!
//! The file is the driver's bytes behind a header of ours: a magic word, a format
//! version, the payload's length and its CRC-32. Reading checks all four and gives
//! nothing on any mismatch (a truncated, damaged or foreign file is ignored and replaced
//! at the next write), because the payload goes to the driver as is: wgpu does not check
//! its hash and Vulkan drivers check only their own header, so damaged bytes past it
//! could reach the driver's parser. The CRC tells damage, not origin: the folder is
//! trusted as the user's own (whoever can write it can write the user's programs too).
//! The driver's own header (vendor, device, driver build) then decides whether the data
//! fit this device.
//!
//! Writes go to a hidden temporary file in the same folder (one per process and write,
//! since the devices of `strata compare`'s warm-up save from threads of one process) and
//! are renamed into place, so a killed run, or two runs or threads saving at once, leave
//! a whole file (the last saver's, which then holds that device's pipelines only) or the
//! old one; a write first removes the temporaries that ended processes left. The cache is
//! an optimisation: a folder that cannot be created or a file that cannot be written is
//! left as it is, silently, and the run goes on.
//!
//! Where: `$XDG_CACHE_HOME/strata`, else `$HOME/.cache/strata` ([`default_folder`]),
//! one file per API and device: `wgpu_pipeline_cache_vulkan_<vendor>_<device>.bin` and
//! `ash_pipeline_cache_vulkan_<vendor>_<device>.bin`. On lavapipe (Mesa 22.3) the
//! driver's data is its header only: there Mesa's own shader cache
//! (`$XDG_CACHE_HOME/mesa_shader_cache`) is what keeps the compiled kernels.

use std::path::{Path, PathBuf};

/// The first bytes of every cache file.
const MAGIC: [u8; 8] = *b"STRATAPC";
/// The layout of the header below; a file of another version is ignored.
const VERSION: u32 = 1;
/// Magic, version, payload length (u64), payload CRC-32: 24 bytes, little-endian.
const HEADER_LENGTH: usize = 8 + 4 + 8 + 4;

/// The cache folder a run uses when nobody chose one: `$XDG_CACHE_HOME/strata`, else
/// `$HOME/.cache/strata`; `None` where neither variable is set (no cache then). A
/// relative path in either is ignored, as the XDG specification asks.
pub fn default_folder() -> Option<PathBuf> {
    let from = |name: &str| std::env::var_os(name).map(PathBuf::from).filter(|path| path.is_absolute());
    from("XDG_CACHE_HOME").or_else(|| from("HOME").map(|home| home.join(".cache"))).map(|base| base.join("strata"))
}

/// One device's pipeline cache file, and what it holds as far as this process knows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PipelineCacheFile {
    path: PathBuf,
    /// The driver's bytes the file holds (read or saved by this process and taken by the
    /// driver): [`Self::save`] writes only what differs.
    on_disk: Option<Vec<u8>>,
}

impl PipelineCacheFile {
    /// The file in `folder` for the device `key` names (API, vendor and device ids).
    pub fn new(folder: &Path, key: &str) -> Self {
        let name: String =
            key.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect();
        Self { path: folder.join(format!("{name}.bin")), on_disk: None }
    }

    /// Where the file is.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The driver's bytes saved by an earlier run, or `None` when there is no file or it
    /// is not whole (wrong magic or version, a length that differs, a CRC that differs).
    pub fn read(&mut self) -> Option<Vec<u8>> {
        self.on_disk = decode(&std::fs::read(&self.path).ok()?);
        self.on_disk.clone()
    }

    /// The driver refused what [`Self::read`] gave: the next [`Self::save`] writes.
    pub fn refused(&mut self) {
        self.on_disk = None;
    }

    /// Writes the driver's bytes if the file does not hold them already (a run whose
    /// pipelines all came from the file leaves it untouched).
    pub fn save(&mut self, payload: &[u8]) {
        if self.on_disk.as_deref() != Some(payload) {
            self.write(payload);
            self.on_disk = Some(payload.to_vec());
        }
    }

    /// Writes the driver's bytes, whole or not at all (module documentation); failures
    /// are ignored.
    pub fn write(&self, payload: &[u8]) {
        let Some(folder) = self.path.parent() else { return };
        if std::fs::create_dir_all(folder).is_err() {
            return;
        }
        let name = self.path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        remove_dead_temporaries(folder, &name);
        // Process and write: threads of one process (strata compare's warm-up devices)
        // save the same device's file at once.
        static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let write = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let temporary = folder.join(format!(".{name}.tmp-{}-{write}", std::process::id()));
        if std::fs::write(&temporary, encode(payload)).is_err() || std::fs::rename(&temporary, &self.path).is_err() {
            let _ = std::fs::remove_file(&temporary);
        }
    }
}

/// Removes the temporaries of the file `name` in `folder` whose process has ended (a
/// run killed while saving: driver caches can be megabytes).
fn remove_dead_temporaries(folder: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    let prefix = format!(".{name}.tmp-");
    for entry in entries.flatten() {
        let entry_name = entry.file_name().to_string_lossy().into_owned();
        // `.NAME.tmp-PID-WRITE`
        let Some((pid, write)) = entry_name.strip_prefix(&prefix).and_then(|rest| rest.split_once('-')) else {
            continue;
        };
        let Some(pid) = crate::processes::writer_between(pid, "", "") else { continue };
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        let numbered = !write.is_empty() && write.bytes().all(|b| b.is_ascii_digit());
        if regular && numbered && pid != std::process::id() && !crate::processes::is_running(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The file's bytes for `payload`.
fn encode(payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER_LENGTH + payload.len());
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&VERSION.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
    bytes.extend_from_slice(payload);
    bytes
}

/// The payload of a file's bytes, if they are whole.
fn decode(bytes: &[u8]) -> Option<Vec<u8>> {
    if bytes.len() < HEADER_LENGTH || bytes[..8] != MAGIC {
        return None;
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().ok()?);
    let length = u64::from_le_bytes(bytes[12..20].try_into().ok()?);
    let crc = u32::from_le_bytes(bytes[20..24].try_into().ok()?);
    let payload = &bytes[HEADER_LENGTH..];
    if version != VERSION || length != payload.len() as u64 || crc != crc32fast::hash(payload) {
        return None;
    }
    Some(payload.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_payload_reads_back_and_anything_damaged_reads_as_nothing() {
        let payload: Vec<u8> = (0..200u32).map(|i| (i * 7) as u8).collect();
        let bytes = encode(&payload);
        assert_eq!(decode(&bytes).as_deref(), Some(&payload[..]));
        assert_eq!(decode(&encode(&[])).as_deref(), Some(&[][..]));
        // One bit of the payload flipped.
        let mut flipped = bytes.clone();
        flipped[HEADER_LENGTH + 100] ^= 4;
        assert_eq!(decode(&flipped), None);
        // Truncated (a file cut short), or longer than its header says.
        assert_eq!(decode(&bytes[..bytes.len() - 1]), None);
        assert_eq!(decode(&bytes[..10]), None);
        assert_eq!(decode(&[bytes.clone(), vec![0]].concat()), None);
        // Another format, or another version of ours.
        assert_eq!(decode(&payload), None);
        let mut later = bytes.clone();
        later[8] = 2;
        assert_eq!(decode(&later), None);
    }

    #[test]
    fn the_file_is_replaced_whole_and_named_after_the_device() {
        let folder = std::env::temp_dir().join(format!("strata-pipeline-cache-unit-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        let mut file = PipelineCacheFile::new(&folder.join("nested"), "wgpu_pipeline_cache_vulkan_4318/7938");
        assert_eq!(file.path().file_name().unwrap(), "wgpu_pipeline_cache_vulkan_4318_7938.bin");
        assert_eq!(file.read(), None);
        file.write(b"first");
        // Temporaries a killed save left (an ended process's) go at the next write; a
        // running process's (another run saving now) stay.
        let ended = crate::processes::an_ended_process();
        let mut running = std::process::Command::new("sleep").arg("60").spawn().unwrap();
        let dead = format!(".wgpu_pipeline_cache_vulkan_4318_7938.bin.tmp-{ended}-3");
        let alive = format!(".wgpu_pipeline_cache_vulkan_4318_7938.bin.tmp-{}-0", running.id());
        for name in [&dead, &alive] {
            std::fs::write(folder.join("nested").join(name), b"half").unwrap();
        }
        file.write(b"second");
        assert_eq!(file.read().as_deref(), Some(&b"second"[..]));
        let _ = running.kill();
        let _ = running.wait();
        let mut names: Vec<_> = std::fs::read_dir(folder.join("nested"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, [alive, "wgpu_pipeline_cache_vulkan_4318_7938.bin".to_string()]);
        // A folder that cannot be created (a file in its way): nothing happens.
        let mut blocked = PipelineCacheFile::new(&file.path().join("below"), "x");
        blocked.write(b"ignored");
        assert_eq!(blocked.read(), None);
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
