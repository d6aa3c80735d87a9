//! Security finding 4, end to end: the Slang driver was run from
//! `$TMPDIR/strata-slang-hlsl-<library>-<length>` whenever a file of that name existed,
//! so whoever wrote that name first in a shared folder decided what ran. This plants a
//! program at exactly that name and checks that `slang::tool()` never hands it out.
//! (One test in its own binary: it sets TMPDIR for the whole process.)

use std::path::PathBuf;

/// Slang's folder as `slang.rs` finds it, if Slang is installed.
fn slang_folder() -> Option<PathBuf> {
    if let Some(folder) = std::env::var_os("STRATA_SLANG_DIR") {
        return Some(PathBuf::from(folder));
    }
    let finder =
        "import importlib.util as u; s = u.find_spec('slangpy'); print(s.submodule_search_locations[0] if s else '')";
    let output = std::process::Command::new("python3").args(["-c", finder]).output().ok()?;
    let folder = String::from_utf8_lossy(&output.stdout).trim().to_string();
    (!folder.is_empty()).then(|| PathBuf::from(folder))
}

#[test]
fn a_program_planted_in_the_shared_temporary_folder_is_never_run() {
    let Some(folder) = slang_folder() else {
        assert!(
            std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none(),
            "Slang is not installed (pip install slangpy)"
        );
        eprintln!("skipped: Slang is not installed");
        return;
    };
    let mut libraries: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("libslang-compiler.so"))
        .collect();
    libraries.sort();
    let library = libraries.pop().expect("Slang's compiler library");
    let shared = strata_files::private_scratch_folder("strata-planted-tmp-").unwrap();
    // SAFETY: the only test of this binary, before any thread is started.
    unsafe { std::env::set_var("TMPDIR", shared.path()) };
    let source_length = include_str!("../src/slang_hlsl.cpp").len();
    let planted = shared.path().join(format!("strata-slang-hlsl-{}-{source_length}", library.replace('.', "_")));
    std::fs::write(&planted, "#!/bin/sh\necho planted > \"$3\"\n").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&planted, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    match strata_kernels::slang::tool() {
        Ok(tool) => assert_ne!(tool, planted, "the planted program would run"),
        Err(error) => panic!("the tool could not be built: {error}"),
    }
}
