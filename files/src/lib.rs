//! # strata-files: file access that someone else's files cannot redirect
//!
//! strata writes images, CSVs, a pipeline cache and packages, reads caches and lock files,
//! and builds and runs a helper tool. Each of these goes through this crate, one module
//! per guard, so that no writer follows a symbolic link planted at a temporary's name, no
//! reader hangs on a named pipe or reads `/dev/zero` until memory runs out, and no
//! program is run from a name someone else could have created first (SECURITY.md says
//! what is trusted and what is not):
//!
//! - [`temporary`]: files created under a random name with `O_CREAT | O_EXCL` (never
//!   through an existing entry, link or not), and the rename that puts them in place;
//! - [`bounded_read`]: whole reads of regular files only, opened without following a
//!   link and without waiting for a pipe's writer, with a size cap checked before reading;
//! - [`private_folder`](mod@private_folder): the per-user cache folder (created `0700`, its owner and mode
//!   checked before anything in it is trusted) and private scratch folders.

pub mod bounded_read;
pub mod private_folder;
pub mod temporary;

pub use tempfile::TempDir;

pub use bounded_read::{ReadError, read_named_regular_capped, read_regular_capped};
pub use private_folder::{
    FolderError, check_private, owned_and_unshared, private_folder, private_scratch_folder, private_scratch_folder_in,
    user_cache_folder, user_cache_path,
};
pub use temporary::{
    TemporaryFile, any_temporary_writer, is_temporary, process_is_running, remove_dead_temporaries, temporary_writer,
    write_whole,
};
