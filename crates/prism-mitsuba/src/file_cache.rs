//! The files a scene names (meshes, curves, grids, images), kept so that a scene built again
//! from an edited description reads none of them twice.
//!
//! The readers take a file's bytes through [`read`], and what they make of them (a mesh)
//! through [`parsed`]: from the cache that [`FileCache::scope`] put in place on this thread,
//! else from disk. A file in the cache is the file as it was when first read; later changes
//! on disk are not seen.

use std::any::Any;
use std::cell::RefCell;
use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

/// A value made of a file (a mesh), by the file's path and the form it was read as.
type Parsed = HashMap<(PathBuf, String), Arc<dyn Any + Send + Sync>>;

/// Files read while building a scene, by path, and the values made of them; a clone shares the
/// same files.
#[derive(Clone, Default)]
pub struct FileCache {
    files: Arc<Mutex<HashMap<PathBuf, Arc<[u8]>>>>,
    parsed: Arc<Mutex<Parsed>>,
}

thread_local! {
    static IN_SCOPE: RefCell<Option<FileCache>> = const { RefCell::new(None) };
}

/// Puts the previous cache (or none) back in scope when dropped, also on a panic.
struct ScopeGuard(Option<FileCache>);

impl Drop for ScopeGuard {
    fn drop(&mut self) {
        IN_SCOPE.with(|cache| *cache.borrow_mut() = self.0.take());
    }
}

impl FileCache {
    /// Runs `f` (a scene build, on this thread) with every file [`read`] takes taken from this
    /// cache, a file not yet in it read from disk and kept.
    pub fn scope<T>(&self, f: impl FnOnce() -> T) -> T {
        let previous = IN_SCOPE.with(|cache| cache.borrow_mut().replace(self.clone()));
        let _guard = ScopeGuard(previous);
        f()
    }

    fn get_or_read(&self, path: &Path) -> io::Result<Arc<[u8]>> {
        let mut files = self.files.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(bytes) = files.get(path) {
            return Ok(bytes.clone());
        }
        let bytes: Arc<[u8]> = std::fs::read(path)?.into();
        files.insert(path.to_path_buf(), bytes.clone());
        Ok(bytes)
    }
}

/// The value `load` makes of the file at `path` read as `form` (a format, and which of its shapes):
/// a copy of the one kept in the cache in scope on this thread (made by `load` and kept the
/// first time), or made by `load` when no cache is in scope.
pub fn parsed<T, E>(path: &Path, form: &str, load: impl FnOnce() -> Result<T, E>) -> Result<T, E>
where
    T: Clone + Send + Sync + 'static,
{
    let Some(cache) = IN_SCOPE.with(|cache| cache.borrow().clone()) else {
        return load();
    };
    let key = (path.to_path_buf(), form.to_string());
    let kept = {
        let parsed = cache.parsed.lock().unwrap_or_else(PoisonError::into_inner);
        parsed.get(&key).cloned()
    };
    if let Some(value) = kept.as_ref().and_then(|kept| kept.downcast_ref::<T>()) {
        return Ok(value.clone());
    }
    let value = load()?;
    let mut parsed = cache.parsed.lock().unwrap_or_else(PoisonError::into_inner);
    parsed.insert(key, Arc::new(value.clone()));
    Ok(value)
}

/// Whether the cache in scope on this thread holds the file at `path` (which then need not
/// exist any more).
pub fn holds(path: &Path) -> bool {
    IN_SCOPE.with(|cache| {
        (cache.borrow().as_ref()).is_some_and(|cache| {
            let files = cache.files.lock().unwrap_or_else(PoisonError::into_inner);
            files.contains_key(path)
        })
    })
}

/// The bytes of the file at `path`: from the cache in scope on this thread (reading the file
/// into it the first time), or from disk when no cache is in scope.
pub fn read(path: &Path) -> io::Result<Arc<[u8]>> {
    match IN_SCOPE.with(|cache| cache.borrow().clone()) {
        Some(cache) => cache.get_or_read(path),
        None => Ok(std::fs::read(path)?.into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_in_the_cache_is_read_once() {
        let dir = std::env::temp_dir().join(format!("prism-file-cache-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("mesh.obj");
        std::fs::write(&path, b"first").unwrap();
        let cache = FileCache::default();
        assert_eq!(&*cache.scope(|| read(&path)).unwrap(), b"first");
        std::fs::remove_file(&path).unwrap();
        assert!(cache.scope(|| holds(&path)) && !holds(&path));
        assert_eq!(&*cache.scope(|| read(&path)).unwrap(), b"first");
        assert!(read(&path).is_err(), "outside the scope the disk is read");
        let mut loads = 0;
        let mut load = || -> Result<usize, ()> {
            loads += 1;
            Ok(loads)
        };
        assert_eq!(cache.scope(|| parsed(&path, "obj", &mut load)), Ok(1));
        assert_eq!(cache.scope(|| parsed(&path, "obj", &mut load)), Ok(1));
        assert_eq!(cache.scope(|| parsed(&path, "ply", &mut load)), Ok(2));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
