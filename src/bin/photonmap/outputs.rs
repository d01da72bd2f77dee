//! The files a run writes: checked before any rendering (each can be
//! created, none is an input, none is named twice), then written
//! atomically, every one of them whatever happens to the others.

use photonmap::error::Error;
use photonmap::output::{check_writable, same_file, Format};
use std::path::{Path, PathBuf};

/// Every output of a run, by role.
#[derive(Debug, Default)]
pub struct Outputs {
    pub images: Vec<PathBuf>,
    pub partial: Option<PathBuf>,
    pub error_map: Option<PathBuf>,
}

impl Outputs {
    pub fn all(&self) -> Vec<(&'static str, &Path)> {
        let mut all: Vec<(&'static str, &Path)> = self.images.iter().map(|p| ("output", p.as_path())).collect();
        all.extend(self.partial.as_deref().map(|p| ("--partial", p)));
        all.extend(self.error_map.as_deref().map(|p| ("--error-map", p)));
        all
    }

    pub fn is_empty(&self) -> bool {
        self.images.is_empty() && self.partial.is_none()
    }

    /// Each output can be written, in a format its role can take, and none
    /// is named twice.
    pub fn check_writable(&self) -> Result<(), Error> {
        let all = self.all();
        for (i, (role, path)) in all.iter().enumerate() {
            let format = check_writable(path)?;
            // Found here, not at the first write: a partial named .png was
            // refused only after the passes it was to hold were rendered.
            let wrong = match (*role, format) {
                ("--partial", Format::Png | Format::Ppm) => Some("a partial render is an .exr file (exact sums)"),
                ("--error-map", Format::Exr) => Some("the error map is an 8-bit picture: .png or .ppm"),
                _ => None,
            };
            if let Some(why) = wrong {
                return Err(Error::Invalid(format!("{role} {}: {why}", path.display())));
            }
            if let Some((other, _)) = all[..i].iter().find(|(_, p)| same_file(p, path)) {
                let roles =
                    if *other == *role { format!("twice as an {role}") } else { format!("as {other} and as {role}") };
                return Err(Error::Invalid(format!(
                    "{}: named {roles}; each output needs its own file",
                    path.display()
                )));
            }
        }
        Ok(())
    }

    /// No output is one of `inputs` (role, path), except that `--partial`
    /// may be the partial that `--resume` extends (it is replaced,
    /// atomically, by one holding more passes).
    pub fn check_not_inputs(&self, inputs: &[(&str, &Path)], resumed: Option<&Path>) -> Result<(), Error> {
        for (role, path) in self.all() {
            for (input_role, input) in inputs {
                if same_file(path, input) {
                    if role == "--partial" && resumed.is_some_and(|r| same_file(r, path)) {
                        continue;
                    }
                    return Err(Error::Invalid(format!(
                        "{}: the {role} is also the {input_role}; it would be overwritten (choose another name)",
                        path.display()
                    )));
                }
            }
        }
        Ok(())
    }
}
