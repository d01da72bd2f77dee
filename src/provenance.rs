//! What an image is a render of: the scene (with a hash of every file it
//! was read from) and the settings that decide its pixels. Written into
//! every EXR's header, and into partial renders' manifests, where it
//! decides which partials may be added together.

use crate::render::settings::Settings;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The scene a render is of.
#[derive(Clone, Debug)]
pub struct SceneId {
    /// As given: the scene file's path, or the built-in room.
    pub name: String,
    /// SHA-256 (hex) of the scene file and every mesh it reads, in order.
    pub hash: String,
    /// The files read (none for the built-in room).
    pub inputs: Vec<PathBuf>,
    /// Stand-ins for what a foreign scene file asked and photonmap could
    /// not render, each with its place (`--substitute`).
    pub substitutions: Vec<String>,
}

impl SceneId {
    pub fn built_in(name: &str) -> SceneId {
        let mut h = Sha256::new();
        h.update(b"built-in scene: ");
        h.update(name.as_bytes());
        SceneId { name: name.to_string(), hash: hex(&h.finalize()), inputs: Vec::new(), substitutions: Vec::new() }
    }

    /// A scene read from `scene` and `meshes`.
    pub fn from_files(scene: &Path, meshes: &[PathBuf]) -> std::io::Result<SceneId> {
        let mut h = Sha256::new();
        let mut inputs = vec![scene.to_path_buf()];
        inputs.extend(meshes.iter().cloned());
        for path in &inputs {
            let mut file = std::fs::File::open(path)?;
            let mut buf = vec![0u8; 1 << 16];
            loop {
                let n = std::io::Read::read(&mut file, &mut buf)?;
                if n == 0 {
                    break;
                }
                h.update(&buf[..n]);
            }
        }
        Ok(SceneId { name: scene.display().to_string(), hash: hex(&h.finalize()), inputs, substitutions: Vec::new() })
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Every setting that decides the pixels, as one line: two renders with
/// the same line and scene make the same image (the thread count is not in
/// it: it changes nothing).
pub fn settings_key(settings: &Settings) -> String {
    format!("{settings:?}")
}

/// How an image was made, for an EXR's header.
pub struct Provenance<'a> {
    pub scene: &'a SceneId,
    pub settings: &'a Settings,
    /// The passes in the image ("0..1" for a classic render).
    pub passes: String,
    /// Photons emitted, every pass's, global and caustic.
    pub photons: u64,
    pub seconds: f64,
}

impl Provenance<'_> {
    /// Header attributes (stored with the prefix `photonmap.`).
    pub fn attributes(&self) -> Vec<(String, String)> {
        let s = self.settings;
        [
            ("scene", self.scene.name.clone()),
            ("scene_sha256", self.scene.hash.clone()),
            ("integrator", s.method.name().to_string()),
            ("seed", s.seed.to_string()),
            ("photons_per_pass", format!("{} global, {} caustic", s.photons, s.caustic_photons)),
            ("photons_emitted", self.photons.to_string()),
            ("passes", self.passes.clone()),
            ("spp", s.spp.to_string()),
            ("wall_seconds", format!("{:.3}", self.seconds)),
            ("settings", settings_key(s)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .chain(
            (!self.scene.substitutions.is_empty())
                .then(|| ("substitutions".to_string(), self.scene.substitutions.join("\n"))),
        )
        .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_cover_every_file() {
        let dir = std::env::temp_dir().join(format!("pm-prov-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (scene, mesh) = (dir.join("s.toml"), dir.join("m.obj"));
        std::fs::write(&scene, "a").unwrap();
        std::fs::write(&mesh, "v 0 0 0").unwrap();
        let a = SceneId::from_files(&scene, std::slice::from_ref(&mesh)).unwrap();
        std::fs::write(&mesh, "v 0 0 1").unwrap();
        let b = SceneId::from_files(&scene, std::slice::from_ref(&mesh)).unwrap();
        assert_ne!(a.hash, b.hash);
        assert_eq!(a.hash.len(), 64);
        assert_ne!(SceneId::built_in("room, eye 1").hash, SceneId::built_in("room, eye 2").hash);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
