//! Output files are written whole or not at all: into a temporary file in the destination
//! directory, renamed into place only when complete.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, format!("cannot create directory: {e}")))?;
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| Error::file(path, format!("cannot write: {e}")))?;
    tmp.write_all(bytes).map_err(|e| Error::file(path, format!("cannot write: {e}")))?;
    // Temporary files are private (0600); an output file gets the usual 0644.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = tmp.as_file().set_permissions(std::fs::Permissions::from_mode(0o644));
    }
    tmp.persist(path).map_err(|e| Error::file(path, format!("cannot write: {}", e.error)))?;
    Ok(())
}

/// Writes several files; all contents exist before the first file is touched, so a failure
/// to prepare any of them leaves nothing behind.
pub fn write_all_atomic(files: &[(std::path::PathBuf, Vec<u8>)]) -> Result<()> {
    for (p, b) in files {
        write_atomic(p, b)?;
    }
    Ok(())
}
