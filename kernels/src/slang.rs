//! A second HLSL front end: the Slang compiler (the library the `slangpy` wheel on PyPI
//! ships), driven by a 40-line C++ tool of ours (`slang_hlsl.cpp`) that this module builds
//! on first use. It compiles naga's HLSL to SPIR-V independently of glslang, so that the
//! HLSL strata exports is compiled, and run, by a compiler other than the one whose bugs
//! strata works around (`glslang.rs`).
//!
//! The tool is built into the per-user cache folder, never found by a fixed name in a
//! shared one ([`tool`]).
//!
//! Where Slang is: `STRATA_SLANG_DIR` (a folder with `include/slang.h` and
//! `libslang-compiler.so*`), else the installed `slangpy` package's folder (found through
//! `python3`). `pip install slangpy` installs it; CI does.

use crate::glslang::{ToolError, run_tool};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The tool's source.
const TOOL_SOURCE: &str = include_str!("slang_hlsl.cpp");

/// The folder with Slang's header and library.
fn slang_folder() -> Result<PathBuf, ToolError> {
    if let Some(folder) = std::env::var_os("STRATA_SLANG_DIR") {
        return Ok(PathBuf::from(folder));
    }
    // Asked of `python3` once per process: every Slang compile asks for the tool, and a
    // Python start per compile (about 90 ms through pyenv's shim on the project's VM) was
    // 58 starts and some 5 CPU-s of tests/tests/corpus.rs alone.
    static INSTALLED: OnceLock<Option<PathBuf>> = OnceLock::new();
    INSTALLED.get_or_init(installed_slangpy_folder).clone().ok_or_else(missing)
}

/// The installed `slangpy` package's folder, asked of `python3`; `None` without Python
/// or the package.
fn installed_slangpy_folder() -> Option<PathBuf> {
    let finder =
        "import importlib.util as u; s = u.find_spec('slangpy'); print(s.submodule_search_locations[0] if s else '')";
    let output = Command::new("python3").args(["-c", finder]).output().ok()?;
    let folder = String::from_utf8_lossy(&output.stdout).trim().to_string();
    (!folder.is_empty()).then(|| PathBuf::from(folder))
}

fn missing() -> ToolError {
    ToolError::Missing("slang (pip install slangpy, or set STRATA_SLANG_DIR)".into())
}

/// Slang's compiler library in `folder` (`libslang-compiler.so` with a version suffix).
fn library(folder: &Path) -> Result<PathBuf, ToolError> {
    let entries = std::fs::read_dir(folder).map_err(|_| missing())?;
    let mut found: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.file_name().and_then(OsStr::to_str).is_some_and(|n| n.starts_with("libslang-compiler.so")))
        .collect();
    found.sort();
    found.pop().ok_or_else(missing)
}

/// A 64-bit FNV-1a hash: names the built tool after its source and Slang library, so a
/// changed source or another Slang is built anew instead of a stale tool being run.
fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &byte in *part {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
        hash ^= 0xff;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// The built tool, building it (with the system's C++ compiler) if it is not there yet.
///
/// Where: `slang-hlsl-<hash>` in the per-user folder `$XDG_CACHE_HOME/strata/tools` (else
/// `~/.cache/strata/tools`), created with mode 0700 and checked to be the user's own and
/// writable by nobody else before anything in it is run ([`strata_files::user_cache_folder`]).
/// It was once built under a fixed name in the shared temporary folder, where anyone
/// could plant a program of that name first and have it run (SECURITY.md). Without a
/// home folder the tool is built into a private folder of this process instead.
pub fn tool() -> Result<PathBuf, ToolError> {
    let folder = slang_folder()?;
    let library = library(&folder)?;
    let hash = fnv1a(&[TOOL_SOURCE.as_bytes(), library.as_os_str().as_encoded_bytes()]);
    let tools = tools_folder()?;
    let built = tools.join(format!("slang-hlsl-{hash:016x}"));
    if is_own_program(&built)? {
        return Ok(built);
    }
    let failed = |path: &Path, e: &dyn std::fmt::Display| ToolError::Failed(format!("{}: {e}", path.display()));
    let scratch = strata_files::private_scratch_folder("strata-slang-build-")
        .map_err(|e| ToolError::Failed(format!("cannot make a private work folder: {e}")))?;
    let source = scratch.path().join("slang_hlsl.cpp");
    std::fs::write(&source, TOOL_SOURCE).map_err(|e| failed(&source, &e))?;
    // Built under a fresh name in the private folder, then renamed into place: two
    // processes building at once each rename a whole program.
    let partial = strata_files::TemporaryFile::beside(&built).map_err(|e| failed(&built, &e))?;
    run_tool(
        "c++",
        &[
            OsStr::new("-std=c++17"),
            OsStr::new("-O1"),
            source.as_os_str(),
            OsStr::new("-I"),
            folder.join("include").as_os_str(),
            library.as_os_str(),
            OsStr::new(&format!("-Wl,-rpath,{}", folder.display())),
            OsStr::new("-o"),
            partial.path().as_os_str(),
        ],
    )?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(partial.path(), std::fs::Permissions::from_mode(0o700))
            .map_err(|e| failed(partial.path(), &e))?;
    }
    partial.persist(&built).map_err(|e| failed(&built, &e))?;
    Ok(built)
}

/// The folder the tool is built in: the per-user `tools` folder, or (no home folder) a
/// private folder of this process, kept until it ends.
fn tools_folder() -> Result<PathBuf, ToolError> {
    match strata_files::user_cache_folder(Some("tools")) {
        Ok(folder) => Ok(folder),
        Err(strata_files::FolderError::NoHome) => {
            static SCRATCH: std::sync::OnceLock<Result<PathBuf, String>> = std::sync::OnceLock::new();
            SCRATCH
                .get_or_init(|| {
                    strata_files::private_scratch_folder("strata-tools-")
                        .map(|dir| dir.keep())
                        .map_err(|e| format!("cannot make a private tools folder: {e}"))
                })
                .clone()
                .map_err(ToolError::Failed)
        }
        Err(error) => Err(ToolError::Failed(error.to_string())),
    }
}

/// Whether `path` is a program this user built: a regular file (not a link) owned by this
/// user and writable by nobody else. Anything else at the name is an error, never run.
fn is_own_program(path: &Path) -> Result<bool, ToolError> {
    let metadata = match std::fs::symlink_metadata(path) {
        Ok(metadata) => metadata,
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(error) => return Err(ToolError::Failed(format!("{}: {error}", path.display()))),
    };
    let refuse = |why: &str| {
        Err(ToolError::Failed(format!("{}: {why}; not run (remove it to have it built again)", path.display())))
    };
    if !metadata.file_type().is_file() {
        return refuse("is not a regular file");
    }
    match strata_files::owned_and_unshared(&metadata) {
        Ok(()) => Ok(true),
        Err(why) => refuse(&why),
    }
}

/// Compiles the HLSL file `hlsl` (compute entry point `entry`) to SPIR-V words.
pub fn compile_hlsl(hlsl: &Path, entry: &str) -> Result<Vec<u32>, ToolError> {
    let tool = tool()?;
    let output = hlsl.with_extension("slang.spv");
    let result = Command::new(&tool)
        .arg(hlsl)
        .arg(entry)
        .arg(&output)
        .output()
        .map_err(|e| ToolError::Failed(format!("{}: {e}", tool.display())))?;
    if !result.status.success() {
        return Err(ToolError::Failed(format!(
            "Slang rejected {}:\n{}",
            hlsl.display(),
            String::from_utf8_lossy(&result.stderr)
        )));
    }
    let bytes = std::fs::read(&output).map_err(|e| ToolError::Failed(format!("{}: {e}", output.display())))?;
    if bytes.len() % 4 != 0 || bytes.len() < 20 {
        return Err(ToolError::Failed(format!("{}: not a SPIR-V file", output.display())));
    }
    let words: Vec<u32> = bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    Ok(with_unknown_source_language(words))
}

/// SPIR-V's `OpSource` opcode.
const OP_SOURCE: u32 = 3;
/// The `SourceLanguage` value `Unknown`.
const SOURCE_LANGUAGE_UNKNOWN: u32 = 0;

/// Rewrites the language operand of every `OpSource` instruction to `Unknown`.
///
/// Why: Slang labels its modules with source language 11 (Slang), newer than the
/// SPIR-V tools inside Debian's Vulkan validation layer, which then reject the whole
/// module as invalid ("Invalid source language operand: 11"). `OpSource` is debug
/// information only, so the rewrite changes no behaviour. Words that do not parse as
/// instructions are returned as they came, for the driver to judge.
pub fn with_unknown_source_language(mut words: Vec<u32>) -> Vec<u32> {
    const HEADER_WORDS: usize = 5;
    let mut at = HEADER_WORDS;
    while at < words.len() {
        let word_count = (words[at] >> 16) as usize;
        let opcode = words[at] & 0xffff;
        if word_count == 0 || at + word_count > words.len() {
            break;
        }
        if opcode == OP_SOURCE && word_count >= 2 {
            words[at + 1] = SOURCE_LANGUAGE_UNKNOWN;
        }
        at += word_count;
    }
    words
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_language_of_op_source_is_rewritten() {
        const MAGIC: u32 = 0x0723_0203;
        const SLANG_LANGUAGE: u32 = 11;
        let op_capability_shader = [(2 << 16) | 17, 1];
        let op_source_slang = [(3 << 16) | OP_SOURCE, SLANG_LANGUAGE, 1];
        let mut words = vec![MAGIC, 0x0001_0300, 0, 100, 0];
        words.extend(op_capability_shader);
        words.extend(op_source_slang);
        let rewritten = with_unknown_source_language(words.clone());
        assert_eq!(rewritten[..7], words[..7], "header and OpCapability untouched");
        assert_eq!(rewritten[7], words[7], "OpSource keeps its opcode and length");
        assert_eq!(rewritten[8], SOURCE_LANGUAGE_UNKNOWN);
        assert_eq!(rewritten[9], 1, "the version operand stays");
    }

    /// Security finding 4: the tool was run from `$TMPDIR/strata-slang-hlsl-<library>-<length>`
    /// if a file of that name existed, so anyone who could write to `/tmp` first decided
    /// what ran. Now a program is looked for only in a private folder, and anything at its
    /// name that is not the user's own regular file, writable by nobody else, is refused.
    #[cfg(unix)]
    #[test]
    fn a_program_planted_at_the_tools_name_is_refused_not_run() {
        use std::os::unix::fs::PermissionsExt;
        let scratch = strata_files::private_scratch_folder("strata-slang-planted-").unwrap();
        let own = scratch.path().join("own");
        std::fs::write(&own, b"#!/bin/sh\n").unwrap();
        std::fs::set_permissions(&own, std::fs::Permissions::from_mode(0o700)).unwrap();
        assert!(is_own_program(&own).unwrap());
        assert!(!is_own_program(&scratch.path().join("absent")).unwrap());
        let writable = scratch.path().join("writable");
        std::fs::write(&writable, b"#!/bin/sh\n").unwrap();
        std::fs::set_permissions(&writable, std::fs::Permissions::from_mode(0o777)).unwrap();
        assert!(is_own_program(&writable).unwrap_err().to_string().contains("others may write"));
        let link = scratch.path().join("link");
        std::os::unix::fs::symlink(&own, &link).unwrap();
        assert!(is_own_program(&link).unwrap_err().to_string().contains("not a regular file"));
    }

    /// The name the tool is found by is never in the shared temporary folder.
    #[test]
    fn the_tools_folder_is_private_and_not_the_shared_temporary_folder() {
        let folder = tools_folder().unwrap();
        strata_files::check_private(&folder).unwrap();
        assert_ne!(folder, std::env::temp_dir());
        assert!(
            !folder.starts_with(std::env::temp_dir())
                || folder.file_name().unwrap().to_string_lossy().starts_with("strata-tools-")
        );
    }

    #[test]
    fn a_truncated_module_comes_back_unchanged() {
        let words = vec![0x0723_0203, 0x0001_0300, 0, 100, 0, (9 << 16) | OP_SOURCE, 11];
        assert_eq!(with_unknown_source_language(words.clone()), words);
    }
}
