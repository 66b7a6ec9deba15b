//! Outputs that are either complete or absent: a file is written under a
//! temporary name in the target's own directory, flushed and synced, and
//! renamed over the target only when complete.
//!
//! The temporary file exists only while the output is written: creating
//! an [`AtomicFile`] checks that it can be made (creates and removes it),
//! so an unwritable target fails before any work, and the first write
//! makes it again. A process killed outright (SIGKILL, the out-of-memory
//! killer) while it computes the output therefore leaves nothing behind.
//! An [`AtomicFile`] that is dropped before [`AtomicFile::commit`] (an
//! error on the way) removes its temporary file. [`remove_on_interrupt`]
//! installs a SIGINT/SIGTERM (Ctrl-C) handler that removes every pending
//! temporary file and exits with status 130, so an interrupted run leaves
//! the old target untouched and nothing beside it. The rename is made
//! under the same lock the handler takes, so an interruption sees either
//! the old target or the complete new one.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Temporary files not yet renamed over their targets.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Outputs renamed over their targets, complete, by this process (under
/// the [`PENDING`] lock).
static COMMITTED: AtomicU64 = AtomicU64::new(0);

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The exit status after an interruption (128 + SIGINT).
pub const INTERRUPTED_EXIT: i32 = 130;

/// Installs the SIGINT/SIGTERM handler (once per process; later calls do
/// nothing): it removes the pending temporary files, says so on stderr
/// (and how many outputs were complete before, which stay) and exits
/// with [`INTERRUPTED_EXIT`].
///
/// # Errors
/// The handler could not be installed.
pub fn remove_on_interrupt() -> Result<(), ctrlc::Error> {
    match ctrlc::set_handler(|| {
        let files = pending();
        for f in files.iter() {
            let _ = std::fs::remove_file(f);
        }
        let (removed, kept) = (files.len(), COMMITTED.load(Ordering::SeqCst));
        let outputs = if kept == 1 { "output" } else { "outputs" };
        match (removed, kept) {
            (_, 0) => eprintln!("rrt: interrupted; no output written"),
            (0, k) => eprintln!("rrt: interrupted; the {k} complete {outputs} written before stay"),
            (_, k) => eprintln!(
                "rrt: interrupted; the output being written was removed, the {k} complete {outputs} written before stay"
            ),
        }
        std::process::exit(INTERRUPTED_EXIT);
    }) {
        Err(ctrlc::Error::MultipleHandlers) => Ok(()),
        r => r,
    }
}

/// A file being written under a temporary name beside its target.
#[derive(Debug)]
pub struct AtomicFile {
    target: PathBuf,
    tmp: PathBuf,
    file: Option<File>,
}

/// The longest file name the temporary name may have (bytes; the limit of
/// common file systems).
const NAME_MAX: usize = 255;

impl AtomicFile {
    /// An output to `target`, written under the temporary name
    /// `NAME.PID-N.tmp` in its directory (`N` counts the outputs of this
    /// process; `.rrt.PID-N.tmp` when that would be longer than 255
    /// bytes). The temporary file is created and removed here, to check
    /// that it can be, and created again by the first [`AtomicFile::file`].
    ///
    /// # Errors
    /// `target` is a directory or has no file name, or the temporary file
    /// cannot be created (missing folder, no permission).
    pub fn create(target: &Path) -> io::Result<Self> {
        static COUNT: AtomicU64 = AtomicU64::new(0);
        if target.is_dir() {
            return Err(io::Error::new(
                io::ErrorKind::IsADirectory,
                "is a directory",
            ));
        }
        let Some(name) = target.file_name() else {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "not a file name",
            ));
        };
        let suffix = format!(
            ".{}-{}.tmp",
            std::process::id(),
            COUNT.fetch_add(1, Ordering::Relaxed)
        );
        // A name that is legal but leaves no room for the suffix within
        // the common 255-byte limit gets the short `.rrt.PID-N.tmp`.
        let mut tmp_name = if name.len().saturating_add(suffix.len()) > NAME_MAX {
            std::ffi::OsString::from(".rrt")
        } else {
            name.to_owned()
        };
        tmp_name.push(suffix);
        let tmp = target.with_file_name(tmp_name);
        let mut out = Self {
            target: target.to_path_buf(),
            tmp,
            file: None,
        };
        out.open()?;
        out.discard();
        Ok(out)
    }

    /// Creates the temporary file, registered before it exists so that an
    /// interruption between the two cannot leave it behind.
    fn open(&mut self) -> io::Result<&mut File> {
        let mut list = pending();
        list.push(self.tmp.clone());
        let file = File::options().write(true).create_new(true).open(&self.tmp);
        if file.is_err() {
            list.retain(|p| *p != self.tmp);
        }
        drop(list);
        Ok(self.file.insert(file?))
    }

    /// The target path.
    #[must_use]
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The temporary path being written.
    #[must_use]
    pub fn temporary(&self) -> &Path {
        &self.tmp
    }

    /// The temporary file, created on the first call.
    ///
    /// # Errors
    /// The temporary file cannot be created (the folder was removed or made
    /// read-only since [`AtomicFile::create`]).
    pub fn file(&mut self) -> io::Result<&mut File> {
        match self.file {
            Some(ref mut f) => Ok(f),
            None => self.open(),
        }
    }

    /// Syncs the temporary file (created empty if nothing was written) and
    /// renames it over the target (then syncs the directory, where the
    /// platform allows).
    ///
    /// # Errors
    /// Syncing or renaming failed; the temporary file is removed and the
    /// target is untouched.
    pub fn commit(mut self) -> io::Result<()> {
        self.file()?;
        let Some(file) = self.file.take() else {
            return Err(io::Error::other("the temporary file is not open"));
        };
        if let Err(e) = file.sync_all() {
            self.discard();
            return Err(e);
        }
        drop(file);
        let mut list = pending();
        let renamed = std::fs::rename(&self.tmp, &self.target);
        if renamed.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        list.retain(|p| *p != self.tmp);
        if renamed.is_ok() {
            COMMITTED.fetch_add(1, Ordering::SeqCst);
        }
        drop(list);
        renamed?;
        #[cfg(unix)]
        if let Some(dir) = self.target.parent() {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            if let Ok(d) = File::open(dir) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }

    fn discard(&mut self) {
        self.file = None;
        let mut list = pending();
        let _ = std::fs::remove_file(&self.tmp);
        list.retain(|p| *p != self.tmp);
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Not committed (an error on the way): remove the temporary file.
        if self.file.is_some() {
            self.discard();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rrt-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn commit_replaces_the_target_and_drop_keeps_it() {
        use std::io::Write;
        let d = dir("commit");
        let target = d.join("x.bin");
        std::fs::write(&target, b"old").unwrap();
        let mut f = AtomicFile::create(&target).unwrap();
        // Nothing beside the target until the first write.
        assert_eq!(names(&d), ["x.bin"]);
        f.file().unwrap().write_all(b"half").unwrap();
        assert_eq!(names(&d).len(), 2);
        drop(f);
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(names(&d), ["x.bin"]);
        let mut f = AtomicFile::create(&target).unwrap();
        f.file().unwrap().write_all(b"new").unwrap();
        f.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(names(&d), ["x.bin"]);
        assert!(pending().is_empty() || !pending().iter().any(|p| p.starts_with(&d)));
        let _ = std::fs::remove_dir_all(&d);
    }

    /// Names up to 255 bytes, legal on common file systems, are written
    /// though the temporary name would be longer than that.
    #[test]
    fn the_longest_names_are_written() {
        use std::io::Write;
        let d = dir("long");
        for len in [243, 244, 250, 255] {
            let target = d.join(format!("{}.png", "a".repeat(len - 4)));
            let mut f = AtomicFile::create(&target).unwrap();
            f.file().unwrap().write_all(b"x").unwrap();
            f.commit().unwrap();
            assert_eq!(std::fs::read(&target).unwrap(), b"x", "{len}");
        }
        assert_eq!(names(&d).len(), 4);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn directories_and_missing_folders_are_refused() {
        let d = dir("refuse");
        assert!(AtomicFile::create(&d).is_err());
        assert!(AtomicFile::create(&d.join("no/such/x.png")).is_err());
        assert!(names(&d).is_empty());
        let _ = std::fs::remove_dir_all(&d);
    }
}
