//! Mitsuba 3's XML read into a tree of elements with their places, with
//! the file-level constructs already applied: `<include>` (spliced in,
//! relative to the including file), `<default>` and `$name` parameters
//! (`-D` values win, as with Mitsuba's `-D`), and `<path>` (folders where
//! `filename` values are looked up). Nothing here knows a plugin.
//!
//! roxmltree parses (it reports each node's line and column); the tree is
//! copied into owned [`Element`]s because included files are separate
//! documents.

use super::Loc;
use crate::scene::file::SceneError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// One XML element after substitution, with where it was written.
#[derive(Debug, Clone)]
pub struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub loc: Loc,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
}

/// What reading the files produced: the root's children (includes spliced
/// in), the search path, and every file read.
pub struct Document {
    pub root: Element,
    pub search: Vec<PathBuf>,
    pub files: Vec<PathBuf>,
}

/// Largest scene file read (a Mitsuba scene's XML holds references to its
/// meshes, not the meshes): beyond it the file is refused, not read
/// without bound.
const MAX_XML_BYTES: u64 = 256 << 20;
/// Deepest chain of includes: a file that includes itself is refused.
const MAX_INCLUDE_DEPTH: usize = 16;

pub fn read(path: &Path, defines: &[(String, String)]) -> Result<Document, SceneError> {
    let mut reader = Reader {
        params: defines.iter().cloned().collect(),
        fixed: defines.iter().map(|(k, _)| k.clone()).collect(),
        search: Vec::new(),
        files: Vec::new(),
    };
    let root = reader.file(path, 0, None)?;
    Ok(Document { root, search: reader.search, files: reader.files })
}

struct Reader {
    params: BTreeMap<String, String>,
    /// Parameters given on the command line: a `<default>` does not change them.
    fixed: Vec<String>,
    search: Vec<PathBuf>,
    files: Vec<PathBuf>,
}

pub fn error(loc: &Loc, field: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError {
        path: loc.file.to_path_buf(),
        line: loc.line,
        column: loc.column,
        field: field.into(),
        message: message.into(),
    }
}

/// The text of a file, refused if it is not a regular file or is too large.
pub fn read_text(path: &Path, what: &str, from: Option<&Loc>) -> Result<String, SceneError> {
    let fail = |message: String| match from {
        Some(loc) => error(loc, "filename", message),
        None => SceneError { path: path.to_path_buf(), line: 0, column: 0, field: "(file)".into(), message },
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read the {what} {}: {e}", path.display())))?;
    if !meta.is_file() {
        return Err(fail(format!("the {what} {} is not a regular file", path.display())));
    }
    if meta.len() > MAX_XML_BYTES {
        return Err(fail(format!(
            "the {what} {} is {} bytes, more than the {} MiB a scene file may hold",
            path.display(),
            meta.len(),
            MAX_XML_BYTES >> 20
        )));
    }
    std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read the {what} {}: {e}", path.display())))
}

impl Reader {
    fn file(&mut self, path: &Path, depth: usize, from: Option<&Loc>) -> Result<Element, SceneError> {
        let text = read_text(path, "scene file", from)?;
        self.files.push(path.to_path_buf());
        let file: Rc<Path> = Rc::from(path);
        let options = roxmltree::ParsingOptions { allow_dtd: false, ..Default::default() };
        let doc = roxmltree::Document::parse_with_options(&text, options).map_err(|e| {
            let pos = e.pos();
            SceneError {
                path: path.to_path_buf(),
                line: pos.row as usize,
                column: pos.col as usize,
                field: "(xml)".into(),
                message: format!("not well-formed XML: {e}"),
            }
        })?;
        let root = doc.root_element();
        let loc = |n: roxmltree::Node| {
            let p = doc.text_pos_at(n.range().start);
            Loc { file: file.clone(), line: p.row as usize, column: p.col as usize }
        };
        let root_loc = loc(root);
        if root.tag_name().name() != "scene" {
            return Err(error(
                &root_loc,
                root.tag_name().name(),
                "a Mitsuba scene file's root element must be <scene>",
            ));
        }
        match root.attribute("version") {
            Some(v) if v.starts_with('2') || v.starts_with('3') => {}
            Some(v) => {
                return Err(error(
                    &root_loc,
                    "scene.version",
                    format!("scene version {v} is not supported (versions 2 and 3 are)"),
                ))
            }
            None => return Err(error(&root_loc, "scene.version", "the <scene> element needs a version attribute")),
        }
        let mut children = Vec::new();
        for node in root.children().filter(|n| n.is_element()) {
            self.top_level(node, &loc, path, depth, &mut children)?;
        }
        Ok(Element { tag: "scene".into(), attrs: Vec::new(), children, loc: root_loc })
    }

    /// A child of `<scene>`: the file-level constructs act here, the rest is kept.
    fn top_level(
        &mut self,
        node: roxmltree::Node,
        loc: &dyn Fn(roxmltree::Node) -> Loc,
        path: &Path,
        depth: usize,
        out: &mut Vec<Element>,
    ) -> Result<(), SceneError> {
        let here = loc(node);
        match node.tag_name().name() {
            "default" => {
                let (name, value) = name_value(node, &here)?;
                if !self.fixed.contains(&name) {
                    self.params.insert(name, value);
                }
            }
            "path" => {
                let value = self.substitute(node.attribute("value").unwrap_or(""), &here, "path.value")?;
                self.search.push(relative_to(path, &value));
            }
            "include" => {
                let Some(name) = node.attribute("filename") else {
                    return Err(error(&here, "include", "an <include> needs a filename"));
                };
                let name = self.substitute(name, &here, "include.filename")?;
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(error(
                        &here,
                        "include",
                        format!("includes nested more than {MAX_INCLUDE_DEPTH} deep (does a file include itself?)"),
                    ));
                }
                // The including file's folder first, then the search path
                // and the first file's folder, as Mitsuba's resolver does.
                let mut tried = vec![relative_to(path, &name)];
                tried.extend(self.search.iter().rev().map(|d| d.join(&name)));
                if let Some(first) = self.files.first() {
                    tried.push(relative_to(first, &name));
                }
                let target = tried.iter().find(|t| t.is_file()).unwrap_or(&tried[0]).clone();
                let included = self.file(&target, depth + 1, Some(&here))?;
                out.extend(included.children);
            }
            _ => out.push(self.element(node, loc)?),
        }
        Ok(())
    }

    fn element(&self, node: roxmltree::Node, loc: &dyn Fn(roxmltree::Node) -> Loc) -> Result<Element, SceneError> {
        let here = loc(node);
        let tag = node.tag_name().name().to_string();
        let mut attrs = Vec::new();
        for a in node.attributes() {
            let field = format!("{tag}.{}", a.name());
            attrs.push((a.name().to_string(), self.substitute(a.value(), &here, &field)?));
        }
        let mut children = Vec::new();
        for c in node.children().filter(|n| n.is_element()) {
            match c.tag_name().name() {
                "default" | "path" | "include" => {
                    return Err(error(
                        &loc(c),
                        c.tag_name().name(),
                        format!("<{}> is allowed only directly inside <scene>", c.tag_name().name()),
                    ))
                }
                _ => children.push(self.element(c, loc)?),
            }
        }
        Ok(Element { tag, attrs, children, loc: here })
    }

    /// `$name` replaced by the parameter's value (a name is letters, digits
    /// and `_`); an undefined one is an error.
    fn substitute(&self, value: &str, loc: &Loc, field: &str) -> Result<String, SceneError> {
        if !value.contains('$') {
            return Ok(value.to_string());
        }
        let mut out = String::new();
        let mut rest = value;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(after.len());
            let name = &after[..len];
            match self.params.get(name) {
                Some(v) if !name.is_empty() => out.push_str(v),
                _ => {
                    return Err(error(
                        loc,
                        field,
                        format!("the parameter ${name} is not defined (give it with -D {name}=VALUE or a <default>)"),
                    ))
                }
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }
}

fn name_value(node: roxmltree::Node, loc: &Loc) -> Result<(String, String), SceneError> {
    match (node.attribute("name"), node.attribute("value")) {
        (Some(n), Some(v)) if !n.is_empty() => Ok((n.to_string(), v.to_string())),
        _ => Err(error(loc, "default", "a <default> needs a name and a value")),
    }
}

fn relative_to(file: &Path, name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        file.parent().unwrap_or(Path::new(".")).join(p)
    }
}
