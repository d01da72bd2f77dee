//! `photonmap info FILE.exr...`: what an image is: its size, channels and
//! how it was made (the header attributes photonmap writes), and for a
//! partial render its manifest.

use crate::error::Error;
use crate::output::partial::{read_partial, Manifest};
use crate::output::{read_exr, read_header};
use std::path::PathBuf;

/// Prints what each file is.
pub fn run(files: &[PathBuf]) -> Result<(), Error> {
    let mut unreadable = Vec::new();
    for (i, path) in files.iter().enumerate() {
        let h = read_header(path)?;
        if i > 0 {
            println!();
        }
        println!("{}: {} x {}", path.display(), h.width, h.height);
        println!("  channels   {}", channel_groups(&h.channels));
        for (key, value) in &h.attributes {
            if key == "manifest" {
                continue;
            }
            println!("  {key:<16} {value}");
        }
        if let Some(json) = h.get("manifest") {
            match serde_json::from_str::<Manifest>(json) {
                Ok(m) => {
                    println!(
                        "  partial render of {} ({}), passes {}",
                        m.scene,
                        &m.scene_hash[..m.scene_hash.len().min(12)],
                        m.passes
                    );
                    println!("  settings   {}", m.settings);
                    for p in &m.parts {
                        println!(
                            "  part       passes {:<12} {:>14} photons {:>10.1} s",
                            p.passes, p.photons, p.seconds
                        );
                    }
                }
                Err(e) => println!("  manifest   unreadable: {e}"),
            }
        }
        // The header comes first in the file: a file cut short (a copy
        // interrupted, a full disk) has a whole header and missing pixels.
        let pixels = match h.get("manifest") {
            Some(_) => read_partial(path).map(|_| ()),
            None => read_exr(path).map(|_| ()),
        };
        if let Err(e) = pixels {
            println!("  pixels     unreadable, the file is truncated or damaged: {e}");
            unreadable.push(path.display().to_string());
        }
    }
    match unreadable.is_empty() {
        true => Ok(()),
        false => Err(Error::Invalid(format!("the pixels of {} cannot be read", unreadable.join(", ")))),
    }
}

/// Channel names grouped by their layer: "R G B, error.{R,G,B}, sums.{00..35}".
fn channel_groups(channels: &[String]) -> String {
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for c in channels {
        let (layer, name) = match c.rsplit_once('.') {
            Some((l, n)) => (l.to_string(), n.to_string()),
            None => (String::new(), c.clone()),
        };
        match groups.iter_mut().find(|(l, _)| *l == layer) {
            Some((_, names)) => names.push(name),
            None => groups.push((layer, vec![name])),
        }
    }
    groups
        .iter()
        .map(|(layer, names)| {
            let list = if names.len() > 4 {
                format!("{}..{} ({})", names[0], names[names.len() - 1], names.len())
            } else {
                names.join(",")
            };
            if layer.is_empty() {
                list
            } else {
                format!("{layer}.{{{list}}}")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}
