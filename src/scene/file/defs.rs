//! The scene file's structure: its top level, and the tables that name
//! their `type` (a material, a shape, a light), each read as that type's
//! own table.
//!
//! A typed table is read in two steps: its `type` first, then the rest of
//! the table as the struct of that type (defined beside the code that
//! builds it), which refuses every field it does not declare. A type's
//! fields are its struct's: nothing else lists them, so the refusal of a
//! field that does not apply to a type cannot drift from what the type
//! reads, and a new field is one line of its type's struct.

use super::camera::CameraDef;
use super::locate::Source;
use super::SceneError;
use serde::de::DeserializeOwned;
use std::collections::BTreeMap;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

pub type V3 = [f32; 3];

/// The top level.
pub struct FileDef<'i> {
    pub camera: Spanned<CameraDef>,
    pub ambient: Option<Spanned<V3>>,
    /// By name, in the order of their names.
    pub materials: BTreeMap<String, Entry<'i>>,
    pub shapes: Vec<Entry<'i>>,
    pub lights: Vec<Entry<'i>>,
    /// Participating media by name, in the order of their names.
    pub media: BTreeMap<String, Entry<'i>>,
    /// Textures by name.
    pub textures: BTreeMap<String, Entry<'i>>,
}

/// The keys of the top level.
const TOP: [&str; 7] = ["camera", "ambient", "materials", "shapes", "lights", "media", "textures"];

impl<'i> FileDef<'i> {
    /// The file's structure, or its first mistake (a syntax error, a key
    /// the top level does not have, a section of the wrong kind).
    pub fn read(src: &Source<'i>) -> Result<FileDef<'i>, SceneError> {
        let root = DeTable::parse(src.text).map_err(|e| src.syntax_error(&e))?;
        let (mut camera, mut ambient) = (None, None);
        let (mut materials, mut shapes, mut lights) = (BTreeMap::new(), Vec::new(), Vec::new());
        let (mut media, mut textures) = (BTreeMap::new(), BTreeMap::new());
        for (key, value) in root.into_inner() {
            match key.get_ref().as_ref() {
                "camera" => camera = Some(src.read(value, "camera")?),
                "ambient" => ambient = Some(src.read(value, "ambient")?),
                "materials" => {
                    for (name, table) in src.table(value, "materials")? {
                        let name = name.into_inner().into_owned();
                        let entry = Entry::new(src, format!("materials.{name}"), table)?;
                        materials.insert(name, entry);
                    }
                }
                "media" => {
                    for (name, table) in src.table(value, "media")? {
                        let name = name.into_inner().into_owned();
                        let entry = Entry::new(src, format!("media.{name}"), table)?;
                        media.insert(name, entry);
                    }
                }
                "textures" => {
                    for (name, table) in src.table(value, "textures")? {
                        let name = name.into_inner().into_owned();
                        let entry = Entry::new(src, format!("textures.{name}"), table)?;
                        textures.insert(name, entry);
                    }
                }
                "shapes" => shapes = src.entries(value, "shapes")?,
                "lights" => lights = src.entries(value, "lights")?,
                other => {
                    let expected = TOP.map(|k| format!("`{k}`")).join(", ");
                    return Err(src.error(
                        key.span(),
                        other,
                        format!("unknown field `{other}`, expected one of {expected}"),
                    ));
                }
            }
        }
        let camera = camera.ok_or_else(|| src.error(0..0, "(top level)", "missing field `camera`"))?;
        Ok(FileDef { camera, ambient, materials, shapes, lights, media, textures })
    }
}

/// A table that names its type: `[materials.NAME]`, `[[shapes]]`,
/// `[[lights]]`.
pub struct Entry<'i> {
    /// Its place in the structure: `shapes[2]`, `materials.glass`.
    pub field: String,
    /// Its `type`.
    pub kind: Spanned<String>,
    /// The rest of the table, until [`Entry::read`] takes it.
    rest: Option<Spanned<DeValue<'i>>>,
}

impl<'i> Entry<'i> {
    pub fn new(src: &Source, field: String, value: Spanned<DeValue<'i>>) -> Result<Entry<'i>, SceneError> {
        let span = value.span();
        let DeValue::Table(mut table) = value.into_inner() else {
            return Err(src.error(span, field, "must be a table (with its `type`)"));
        };
        let Some(kind) = table.remove("type") else {
            return Err(src.error(span, format!("{field}.type"), "missing field `type`"));
        };
        let kind_span = kind.span();
        let DeValue::String(name) = kind.into_inner() else {
            return Err(src.error(kind_span, format!("{field}.type"), "invalid type: expected a string"));
        };
        let kind = Spanned::new(kind_span, name.into_owned());
        Ok(Entry { field, kind, rest: Some(Spanned::new(span, DeValue::Table(table))) })
    }

    /// Takes key `key` out of the table, before [`Entry::read`] reads the
    /// rest: a field every type of the section has (a shape's media).
    pub fn take(&mut self, key: &str) -> Option<Spanned<DeValue<'i>>> {
        match self.rest.as_mut().map(|r| r.get_mut()) {
            Some(DeValue::Table(t)) => t.remove(key),
            _ => None,
        }
    }

    /// The rest of the table, key by key (for a type whose fields are
    /// listed by `material::params`).
    pub fn fields(&mut self) -> Vec<(Spanned<String>, Spanned<DeValue<'i>>)> {
        match self.rest.take().map(|r| r.into_inner()) {
            Some(DeValue::Table(t)) => t
                .into_iter()
                .map(|(k, v)| {
                    let span = k.span();
                    (Spanned::new(span, k.into_inner().into_owned()), v)
                })
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Its `type`, for checks (the field `…type`).
    pub fn kind(&self) -> super::build::At<'_, String> {
        super::build::at(&self.kind, format!("{}.type", self.field))
    }

    /// The rest of the table as its type's struct `T`. A field `T` does
    /// not declare is refused at its key, and a missing one at the `type`,
    /// each named by its place (`shapes[2].radius`).
    pub fn read<T: DeserializeOwned>(&mut self, src: &Source) -> Result<T, SceneError> {
        let Some(rest) = self.rest.take() else {
            return Err(src.error(self.kind.span(), self.field.clone(), "read twice"));
        };
        let kind = self.kind.get_ref();
        src.read(rest, &self.field).map_err(|mut e| {
            if let Some(name) = quoted_after(&e.message, "missing field `") {
                e = src.error(
                    self.kind.span(),
                    format!("{}.{name}", self.field),
                    format!("missing field `{name}` (required for type \"{kind}\")"),
                );
            } else if let Some(name) = quoted_after(&e.message, "unknown field `") {
                let takes = match e.message.split_once(", expected ") {
                    Some((_, fields)) => fields.trim_start_matches("one of ").to_string(),
                    None => "no field besides `type`".to_string(),
                };
                e.message =
                    format!("unknown field `{name}`: it does not apply to type \"{kind}\", which takes {takes}");
            }
            e
        })
    }
}

/// The text between `prefix` and the next backquote.
fn quoted_after<'m>(message: &'m str, prefix: &str) -> Option<&'m str> {
    message.strip_prefix(prefix)?.split('`').next()
}

impl<'i> Source<'i> {
    /// A section that must be a table: its entries.
    fn table(&self, value: Spanned<DeValue<'i>>, field: &str) -> Result<DeTable<'i>, SceneError> {
        let span = value.span();
        match value.into_inner() {
            DeValue::Table(t) => Ok(t),
            other => Err(self.error(span, field, format!("invalid type: {}, expected a table", other.type_str()))),
        }
    }

    /// A section that is an array of typed tables (`[[shapes]]`).
    fn entries(&self, value: Spanned<DeValue<'i>>, field: &str) -> Result<Vec<Entry<'i>>, SceneError> {
        let span = value.span();
        let DeValue::Array(items) = value.into_inner() else {
            return Err(self.error(span, field, "invalid type: expected an array of tables ([[…]])"));
        };
        items.into_iter().enumerate().map(|(i, item)| Entry::new(self, format!("{field}[{i}]"), item)).collect()
    }

    /// `value` as a `T`; a mistake is named by its path below `field`.
    pub fn read<'v, T: DeserializeOwned>(&self, value: Spanned<DeValue<'v>>, field: &str) -> Result<T, SceneError> {
        let span = value.span();
        serde_path_to_error::deserialize(toml::de::ValueDeserializer::from(value)).map_err(|e| {
            let below = super::locate::field_path(e.path());
            let path = match below.as_str() {
                "" => field.to_string(),
                b if b.starts_with('[') => format!("{field}{b}"),
                b => format!("{field}.{b}"),
            };
            let inner = e.into_inner();
            self.error(inner.span().unwrap_or(span), path, inner.message().trim().to_string())
        })
    }
}
