//! Where the scene loaders read their files from: the disk ([`DiskFiles`], what
//! [`super::load_scene_file`] uses) or a map of names to bytes ([`MemoryFiles`], for
//! loading a scene held in memory, as the fuzz harness does). Every loader reads the scene
//! file and everything it names (meshes, buffers, material libraries, textures,
//! environment maps) through one [`FileSource`], so nothing else touches the file system.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Something that hands out the bytes of a file by its path.
pub trait FileSource {
    /// The whole contents of `path` (paths are joined to the scene file's folder by the
    /// loaders before they ask).
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>>;
}

/// The file system.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiskFiles;

impl FileSource for DiskFiles {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        read_capped(path)
    }
}

/// The most bytes strata reads from a pipe: 1 GiB, above any of the shared scenes' files
/// by a wide margin. An endless one is an error naming it, never read until memory runs
/// out; a device such as `/dev/zero` is refused before anything is read. A regular
/// file is read whole: its size is known before reading.
pub const MAX_INPUT_FILE_BYTES: u64 = 1 << 30;

/// The whole contents of `path`: a regular file as it is, a pipe up to
/// [`MAX_INPUT_FILE_BYTES`] and refused beyond it, a device or socket refused at once. Every file read is noted
/// as an input of the run ([`crate::atomic_file::note_input`]).
///
/// A named pipe is opened without waiting for a writer (`O_NONBLOCK`): one
/// that nobody writes to reads as empty (and its loader names it), where a plain `open`
/// would wait forever.
pub fn read_capped(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let file = open_without_waiting(path)?;
    let metadata = file.metadata()?;
    if metadata.is_dir() {
        return Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, "is a folder, not a file"));
    }
    // A device (`/dev/zero`, `/dev/urandom`) is never a scene, image or table: refused at
    // once rather than read to the cap (a pipe may be one, `<(cat scene.json)`, and is
    // read).
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = metadata.file_type();
        if kind.is_char_device() || kind.is_block_device() || kind.is_socket() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is a device, not a regular file: never read",
            ));
        }
    }
    // No output of this run may replace what it reads.
    crate::atomic_file::note_input(path);
    let mut bytes = Vec::new();
    if metadata.is_file() {
        // A regular file's size is what the user handed over: read as it is.
        bytes.reserve_exact(usize::try_from(metadata.len()).unwrap_or(0));
        (&file).read_to_end(&mut bytes)?;
        return Ok(bytes);
    }
    read_waiting_for_writers(file, &mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_FILE_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not a regular file, and more than the {} MiB read from a pipe", MAX_INPUT_FILE_BYTES >> 20),
        ));
    }
    Ok(bytes)
}

/// Opens `path` for reading; on Unix with `O_NONBLOCK`, so that opening a named pipe
/// returns at once instead of waiting for a writer to appear (for a regular file or a
/// device the flag changes nothing that [`read_capped`] does).
fn open_without_waiting(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// Reads a device or pipe opened by [`open_without_waiting`] to its end, at most one byte
/// beyond [`MAX_INPUT_FILE_BYTES`]: a pipe with a writer that has not written yet says
/// "would block", and is waited for in short sleeps; one without a writer ends at once.
fn read_waiting_for_writers(file: std::fs::File, bytes: &mut Vec<u8>) -> std::io::Result<()> {
    use std::io::Read;
    let mut limited = file.take(MAX_INPUT_FILE_BYTES + 1);
    loop {
        match limited.read_to_end(bytes) {
            Ok(_) => return Ok(()),
            Err(error) if error.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
            Err(error) => return Err(error),
        }
    }
}

/// [`read_capped`] as UTF-8 text, without a leading byte order mark ([`without_bom`]).
pub fn read_text_capped(path: &Path) -> std::io::Result<String> {
    let mut bytes = read_capped(path)?;
    let mark = bytes.len() - without_bom(&bytes).len();
    bytes.drain(..mark);
    String::from_utf8(bytes).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// The UTF-8 byte order mark (U+FEFF) that some editors (Windows Notepad among them) put
/// at the start of a text file.
pub const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// `bytes` without a leading UTF-8 byte order mark: the one place every text reader
/// (JSON scenes and camera paths, glTF JSON, OBJ and MTL, PLY headers, `errors.csv`)
/// drops it, so that a file saved "as UTF-8 with BOM" reads as the same text (a JSON
/// parser refused it at line 1 column 1; in an MTL file it hid the first `newmtl`).
/// Binary formats never start with these bytes (a GLB starts with `glTF`).
pub fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(UTF8_BOM).unwrap_or(bytes)
}

/// Files held in memory, by path; a path not in the map is "not found", unless a
/// fallback by extension answers for it.
#[derive(Clone, Debug, Default)]
pub struct MemoryFiles {
    /// Contents by exact path.
    pub files: HashMap<PathBuf, Vec<u8>>,
    /// Contents for any other path with this (lower-case) extension, e.g. `ply`.
    pub by_extension: HashMap<String, Vec<u8>>,
}

impl MemoryFiles {
    /// Adds (or replaces) the file `path`.
    pub fn insert(&mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) -> &mut Self {
        self.files.insert(path.into(), bytes.into());
        self
    }
}

impl FileSource for MemoryFiles {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        if let Some(bytes) = self.files.get(path) {
            return Ok(bytes.clone());
        }
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.and_then(|e| self.by_extension.get(&e)) {
            Some(bytes) => Ok(bytes.clone()),
            None => Err(std::io::ErrorKind::NotFound.into()),
        }
    }
}

/// Reads `path` through `files`, as a [`super::SceneError::Io`] naming it on failure.
pub(super) fn read(files: &dyn FileSource, path: &Path) -> Result<Vec<u8>, super::SceneError> {
    files.read(path).map_err(|source| super::SceneError::Io { path: path.into(), source })
}

/// Reads the text file `path` through `files` as UTF-8, without a leading byte order
/// mark; bytes that are not UTF-8 are a [`super::SceneError::Io`] naming the file.
pub(super) fn read_text(files: &dyn FileSource, path: &Path) -> Result<String, super::SceneError> {
    let bytes = read(files, path)?;
    String::from_utf8(without_bom(&bytes).to_vec()).map_err(|source| super::SceneError::Io {
        path: path.into(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidData, source),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_order_mark_is_dropped_once_and_only_at_the_start() {
        assert_eq!(without_bom(b"\xEF\xBB\xBF{}"), b"{}");
        assert_eq!(without_bom(b"\xEF\xBB\xBF\xEF\xBB\xBF{}"), b"\xEF\xBB\xBF{}");
        assert_eq!(without_bom(b"{\xEF\xBB\xBF}"), b"{\xEF\xBB\xBF}");
        assert_eq!(without_bom(b"\xEF\xBB"), b"\xEF\xBB");
        let mut files = MemoryFiles::default();
        files.insert("a.json", b"\xEF\xBB\xBF{\"a\": 1}\r\n".to_vec()).insert("b.json", vec![0xEF, 0xBB, 0xBF, 0xFF]);
        assert_eq!(read_text(&files, Path::new("a.json")).unwrap(), "{\"a\": 1}\r\n");
        let error = read_text(&files, Path::new("b.json")).unwrap_err().to_string();
        assert!(error.contains("b.json"), "{error}");
    }
}
