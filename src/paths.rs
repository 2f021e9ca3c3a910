//! Which file a path names, for refusing to write over what must not be written over
//! (the database being run, the trace with its own GIF) and for writing through links.

use std::path::{Path, PathBuf};

/// The file a path names, through any symbolic links (the path itself if it does not
/// exist yet; a dangling link names where it points).
pub fn resolve_links(path: &Path) -> std::io::Result<PathBuf> {
    match std::fs::canonicalize(path) {
        Ok(target) => Ok(target),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => match std::fs::read_link(path) {
            Ok(points_to) => Ok(path.parent().unwrap_or(Path::new(".")).join(points_to)),
            Err(_) => Ok(path.to_path_buf()),
        },
        Err(e) => Err(e),
    }
}

/// Where writing `path` puts the bytes, as one absolute path: through its links, in its
/// folder's canonical path (a file that does not exist yet is where it would be).
fn destination(path: &Path) -> Option<PathBuf> {
    let target = resolve_links(path).ok()?;
    if let Ok(existing) = target.canonicalize() {
        return Some(existing);
    }
    let name = target.file_name()?;
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Some(folder.canonicalize().ok()?.join(name))
}

/// Whether `a` and `b` are, or would be, the same file: the same device and inode where
/// both exist (a hard link has another path), else the same destination.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        use std::os::unix::fs::MetadataExt;
        return ma.dev() == mb.dev() && ma.ino() == mb.ino();
    }
    matches!((destination(a), destination(b)), (Some(x), Some(y)) if x == y)
}
