//! Where in the file a mistake is: byte spans turned into line and column,
//! and the field named by its path in the scene's structure.

use super::SceneError;
use std::ops::Range;
use std::path::Path;

/// The text being read, for turning spans into lines and columns.
#[derive(Clone, Copy)]
pub struct Source<'a> {
    pub path: &'a Path,
    pub text: &'a str,
    /// The byte offset where each line starts ([`line_starts`]): every
    /// entry's place is looked up, and counting lines from the file's start
    /// each time made loading quadratic in the number of entries (100,000
    /// spheres took about 12 minutes).
    pub line_starts: &'a [usize],
}

/// The byte offsets at which the lines of `text` start (0 first).
pub fn line_starts(text: &str) -> Vec<usize> {
    std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect()
}

impl Source<'_> {
    pub fn error(&self, span: Range<usize>, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        let (line, column) = self.line_column(span.start);
        SceneError { path: self.path.to_path_buf(), line, column, field: field.into(), message: message.into() }
    }

    /// The 1-based line and column (in characters) of a byte offset.
    fn line_column(&self, offset: usize) -> (usize, usize) {
        let mut start = offset.min(self.text.len());
        while !self.text.is_char_boundary(start) {
            start -= 1;
        }
        // The number of lines starting at or before the offset.
        let line = self.line_starts.partition_point(|&s| s <= start).max(1);
        let line_start = self.line_starts.get(line - 1).copied().unwrap_or(0).min(start);
        (line, self.text[line_start..start].chars().count() + 1)
    }

    /// A syntax error, named by the table it is in: the header on its own
    /// line (a duplicated `[camera]`), else the last header before it.
    pub(super) fn syntax_error(&self, e: &toml::de::Error) -> SceneError {
        let span = e.span().unwrap_or(0..0);
        self.error(span.clone(), self.table_at(span.start), e.message().trim().to_string())
    }

    fn table_at(&self, offset: usize) -> String {
        let offset = offset.min(self.text.len());
        let line_end = self.text[offset..].find('\n').map_or(self.text.len(), |i| offset + i);
        let mut table = "(top level)".to_string();
        let mut counts = std::collections::BTreeMap::<String, usize>::new();
        for line in self.text[..line_end].lines() {
            let t = line.trim();
            if let Some(name) = t.strip_prefix("[[").and_then(|r| r.split("]]").next()) {
                let name = name.trim().to_string();
                let n = counts.entry(name.clone()).or_insert(0);
                table = format!("{name}[{n}]");
                *n += 1;
            } else if let Some(name) = t.strip_prefix('[').and_then(|r| r.split(']').next()) {
                table = name.trim().to_string();
            }
        }
        table
    }
}

/// A path in the structure as the scene format names it, `radius` or
/// `transform[1].scale` (empty: the value itself): the wrapper that carries
/// each value's span is not a field of the format.
pub(super) fn field_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for segment in path.iter() {
        match segment {
            Segment::Seq { index } => out += &format!("[{index}]"),
            Segment::Map { key } | Segment::Enum { variant: key } if key.starts_with("$__serde_spanned") => {}
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out += key;
            }
            Segment::Unknown => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The line and column as counted from the file's start, the way the
    /// index must answer.
    fn counted(text: &str, offset: usize) -> (usize, usize) {
        let before = &text[..offset];
        (before.matches('\n').count() + 1, before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1)
    }

    #[test]
    fn the_line_index_answers_as_counting_from_the_start() {
        let text = "[camera]\neye = [0, 0, 1]\n\n# caf\u{e9} \u{2014} \r\n[[shapes]]\ntype = \"sphere\"\n\nlast";
        let starts = line_starts(text);
        let src = Source { path: Path::new("s.toml"), text, line_starts: &starts };
        for offset in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
            assert_eq!(src.line_column(offset), counted(text, offset), "offset {offset}");
        }
        // Past the end: the end.
        assert_eq!(src.line_column(text.len() + 10), counted(text, text.len()));
        let empty = Source { path: Path::new("e.toml"), text: "", line_starts: &line_starts("") };
        assert_eq!(empty.line_column(0), (1, 1));
    }
}
