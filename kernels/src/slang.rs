//! A second HLSL front end: the Slang compiler (the library the `slangpy` wheel on PyPI
//! ships), driven by a 40-line C++ tool of ours (`slang_hlsl.cpp`) that this module builds
//! on first use. It compiles naga's HLSL to SPIR-V independently of glslang, so that the
//! HLSL strata exports is compiled, and run, by a compiler other than the one whose bugs
//! strata works around (`glslang.rs`).
//!
//! Where Slang is: `STRATA_SLANG_DIR` (a folder with `include/slang.h` and
//! `libslang-compiler.so*`), else the installed `slangpy` package's folder (found through
//! `python3`). `pip install slangpy` installs it; CI does.

use crate::glslang::{ToolError, run_tool};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The tool's source.
const TOOL_SOURCE: &str = include_str!("slang_hlsl.cpp");

/// The folder with Slang's header and library.
fn slang_folder() -> Result<PathBuf, ToolError> {
    if let Some(folder) = std::env::var_os("STRATA_SLANG_DIR") {
        return Ok(PathBuf::from(folder));
    }
    let finder =
        "import importlib.util as u; s = u.find_spec('slangpy'); print(s.submodule_search_locations[0] if s else '')";
    let output = Command::new("python3").args(["-c", finder]).output().map_err(|_| missing())?;
    let folder = String::from_utf8_lossy(&output.stdout).trim().to_string();
    if folder.is_empty() {
        return Err(missing());
    }
    Ok(PathBuf::from(folder))
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

/// The built tool, building it (with the system's C++ compiler) if it is not there yet.
pub fn tool() -> Result<PathBuf, ToolError> {
    let folder = slang_folder()?;
    let library = library(&folder)?;
    let version = library.file_name().and_then(OsStr::to_str).unwrap_or("slang").replace('.', "_");
    let built = std::env::temp_dir().join(format!("strata-slang-hlsl-{version}-{}", TOOL_SOURCE.len()));
    if built.is_file() {
        return Ok(built);
    }
    let source = built.with_extension("cpp");
    std::fs::write(&source, TOOL_SOURCE).map_err(|e| ToolError::Failed(format!("{}: {e}", source.display())))?;
    let partial = built.with_extension("partial");
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
            partial.as_os_str(),
        ],
    )?;
    std::fs::rename(&partial, &built).map_err(|e| ToolError::Failed(format!("{}: {e}", built.display())))?;
    Ok(built)
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

    #[test]
    fn a_truncated_module_comes_back_unchanged() {
        let words = vec![0x0723_0203, 0x0001_0300, 0, 100, 0, (9 << 16) | OP_SOURCE, 11];
        assert_eq!(with_unknown_source_language(words.clone()), words);
    }
}
