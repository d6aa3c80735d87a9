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
//! Writes go to a hidden temporary file in the same folder, created under a random name
//! that nothing planted can redirect ([`strata_files::TemporaryFile`]: one per write,
//! since the devices of `strata compare`'s warm-up save from threads of one process), and
//! are renamed into place, so a killed run, or two runs or threads saving at once, leave
//! a whole file (the last saver's, which then holds that device's pipelines only) or the
//! old one; a write first removes the temporaries that ended processes left.
//!
//! The folder must be the user's own: it is created with mode 0700, and a folder that is
//! a link, belongs to someone else or that others may write is not used at all (nothing
//! read from it, nothing written), since its bytes reach the driver. The file is read
//! through [`strata_files::read_regular_capped`]: a link, a named pipe or a device at its
//! name (a link to `/dev/zero`) is ignored at once, never followed, waited on or read, and
//! a file over [`MAX_CACHE_FILE_BYTES`] is ignored. The cache is an optimisation: a
//! folder that cannot be created or a file that cannot be read or written is left as it
//! is, silently, and the run goes on.
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

/// The largest cache file read: drivers' caches of strata's kernels are kilobytes to a
/// few megabytes; anything larger is not ours and is ignored.
pub const MAX_CACHE_FILE_BYTES: u64 = 256 << 20;

/// The cache folder a run uses when nobody chose one: `$XDG_CACHE_HOME/strata`, else
/// `$HOME/.cache/strata`; `None` where neither variable is set (no cache then). A
/// relative path in either is ignored, as the XDG specification asks.
pub fn default_folder() -> Option<PathBuf> {
    strata_files::private_folder::user_cache_path()
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
    /// Nothing is read from a folder that is not private (module documentation), and only
    /// a regular file of at most [`MAX_CACHE_FILE_BYTES`] is read.
    pub fn read(&mut self) -> Option<Vec<u8>> {
        strata_files::check_private(self.path.parent()?).ok()?;
        self.on_disk = decode(&strata_files::read_regular_capped(&self.path, MAX_CACHE_FILE_BYTES).ok()?);
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
    /// are ignored, and nothing is written into a folder that is not private.
    pub fn write(&self, payload: &[u8]) {
        use std::io::Write;
        let Some(folder) = self.path.parent() else { return };
        if strata_files::private_folder(folder).is_err() {
            return;
        }
        strata_files::remove_dead_temporaries(&self.path);
        let Ok(temporary) = strata_files::TemporaryFile::beside(&self.path) else { return };
        let mut file = temporary.file();
        if file.write_all(&encode(payload)).is_ok() && file.sync_all().is_ok() {
            let _ = temporary.persist(&self.path);
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
        let scratch = strata_files::private_scratch_folder("strata-pipeline-cache-unit-").unwrap();
        let folder = scratch.path().to_path_buf();
        let mut file = PipelineCacheFile::new(&folder.join("nested"), "wgpu_pipeline_cache_vulkan_4318/7938");
        assert_eq!(file.path().file_name().unwrap(), "wgpu_pipeline_cache_vulkan_4318_7938.bin");
        assert_eq!(file.read(), None);
        file.write(b"first");
        // Temporaries a killed save left (an ended process's) go at the next write; a
        // running process's (another run saving now) stay.
        let ended = crate::processes::an_ended_process();
        let mut running = std::process::Command::new("sleep").arg("60").spawn().unwrap();
        let dead = format!(".wgpu_pipeline_cache_vulkan_4318_7938.tmp-{ended}-a3.bin");
        let alive = format!(".wgpu_pipeline_cache_vulkan_4318_7938.tmp-{}-b0.bin", running.id());
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
    }

    /// Security finding 7: a named pipe at the cache's path hung `strata render --backend
    /// wgpu` (a plain read waits for a writer), and a link to `/dev/zero` was read until
    /// memory ran out. Both are ignored at once now, and so is a folder others may write.
    #[cfg(unix)]
    #[test]
    fn a_pipe_a_device_link_or_a_shared_folder_at_the_cache_is_ignored_at_once() {
        use std::os::unix::fs::PermissionsExt;
        let scratch = strata_files::private_scratch_folder("strata-pipeline-cache-hostile-").unwrap();
        let mut fifo = PipelineCacheFile::new(scratch.path(), "fifo");
        let name = std::ffi::CString::new(fifo.path().as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path; mkfifo only creates the entry.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        let (sender, receiver) = std::sync::mpsc::channel();
        std::thread::spawn(move || sender.send(fifo.read()).unwrap());
        let read = receiver.recv_timeout(std::time::Duration::from_secs(10)).expect("reading a named pipe hung");
        assert_eq!(read, None);
        let mut zero = PipelineCacheFile::new(scratch.path(), "zero");
        std::os::unix::fs::symlink("/dev/zero", zero.path()).unwrap();
        assert_eq!(zero.read(), None);
        // A whole, valid file in a folder others may write is not read, and not replaced.
        let shared = scratch.path().join("shared");
        std::fs::create_dir(&shared).unwrap();
        let mut planted = PipelineCacheFile::new(&shared, "key");
        std::fs::write(planted.path(), encode(b"someone else's")).unwrap();
        std::fs::set_permissions(&shared, std::fs::Permissions::from_mode(0o777)).unwrap();
        assert_eq!(planted.read(), None);
        planted.write(b"ours");
        assert_eq!(std::fs::read(planted.path()).unwrap(), encode(b"someone else's"));
    }
}
