//! A private `XDG_RUNTIME_DIR` for the adapter probe (see [`PrivateRuntimeDir`]).

/// A runtime directory of this process's own, for the adapter probe.
///
/// Making a Vulkan instance loads Mesa's device-select layer, which asks a Wayland compositor
/// for the default GPU where it can; without an absolute `XDG_RUNTIME_DIR`, libwayland prints
/// `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` for that (twice), a line
/// that looks like a dustdem error and is about a display that a compute job never uses. With
/// a runtime directory the connection attempt fails quietly and nothing else changes: the
/// simulation draws nothing.
///
/// [`PrivateRuntimeDir::ensure`] makes one where `XDG_RUNTIME_DIR` is unset, not absolute or
/// not a directory: a fresh directory in the system temp folder, mode 0700, removed with its
/// contents when the guard is dropped. `dustdem -v` skips it, so the libraries' own messages
/// stay visible.
#[derive(Debug)]
pub struct PrivateRuntimeDir(std::path::PathBuf);

impl PrivateRuntimeDir {
    /// Sets `XDG_RUNTIME_DIR` to a new private directory where it is not usable (`None` where
    /// it is, or where no directory could be made). Changes the environment, so it must run
    /// before any other thread starts: `main` calls it first.
    pub fn ensure() -> Option<PrivateRuntimeDir> {
        let usable = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|dir| {
            let dir = std::path::Path::new(&dir);
            dir.is_absolute() && dir.is_dir()
        });
        if usable {
            return None;
        }
        let dir = Self::create()?;
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
        Some(PrivateRuntimeDir(dir))
    }

    pub fn path(&self) -> &std::path::Path {
        &self.0
    }

    /// `dustdem-runtime-<pid>` (or `-<pid>-<k>` if that exists) in the temp folder, mode 0700.
    fn create() -> Option<std::path::PathBuf> {
        let base = std::path::absolute(std::env::temp_dir()).ok()?;
        let pid = std::process::id();
        (0..100).find_map(|k| {
            let name = if k == 0 {
                format!("dustdem-runtime-{pid}")
            } else {
                format!("dustdem-runtime-{pid}-{k}")
            };
            let dir = base.join(name);
            let mut builder = std::fs::DirBuilder::new();
            #[cfg(unix)]
            std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
            builder.create(&dir).ok().map(|()| dir)
        })
    }
}

impl Drop for PrivateRuntimeDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
