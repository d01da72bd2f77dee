//! The figures README.md and notes/*.md quote are notes/results.csv's, the
//! one file `tools/results.py` measures and writes: a quoted figure is a
//! number followed by `<!--r:KEY-->`, and must read as the file's value for
//! KEY rounded to the decimals it is written with. A figure restated by hand
//! that drifts from the measurement fails here; `tools/results.py --quote`
//! rewrites them all from the file.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

const FIELDS: [&str; 7] = ["key", "value", "unit", "command", "commit", "machine", "date"];
const MARKER: &str = "<!--r:";

/// The results file's values by key; what is wrong with it otherwise.
fn read_results(text: &str) -> Result<HashMap<String, f64>, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty")?.split(',').collect();
    if header != FIELDS {
        return Err(format!("header {header:?}, expected {FIELDS:?}"));
    }
    let mut values = HashMap::new();
    for (i, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != FIELDS.len() {
            return Err(format!("line {}: {} fields, expected {}", i + 2, f.len(), FIELDS.len()));
        }
        let value: f64 = f[1].parse().map_err(|_| format!("line {}: value '{}' is not a number", i + 2, f[1]))?;
        if f[3].is_empty() || f[4].is_empty() || f[5].is_empty() || f[6].is_empty() {
            return Err(format!("line {}: {} has no command, commit, machine or date", i + 2, f[0]));
        }
        if values.insert(f[0].to_string(), value).is_some() {
            return Err(format!("line {}: key {} twice", i + 2, f[0]));
        }
    }
    Ok(values)
}

/// A figure quoted in a text: its line, key, and the number as written.
#[derive(Debug, PartialEq)]
struct Quote {
    line: usize,
    key: String,
    written: Option<String>,
}

/// Every marker of `text` with the number just before it on its line (a
/// unit, `%`, `**` or a space may stand between them).
fn quotes(text: &str) -> Vec<Quote> {
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut from = 0;
        while let Some(at) = line[from..].find(MARKER) {
            let start = from + at;
            let rest = &line[start + MARKER.len()..];
            let key = rest.split("-->").next().unwrap_or("").to_string();
            from = start + MARKER.len();
            found.push(Quote { line: i + 1, key, written: number_before(&line[..start]) });
        }
    }
    found
}

/// The last number in `s` (digits with `,` grouping and a `.`, an
/// optional sign), if at most a short unit separates it from the end.
fn number_before(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut end = b.len();
    while end > 0 && !b[end - 1].is_ascii_digit() {
        end -= 1;
        if b.len() - end > 4 {
            return None;
        }
    }
    let mut start = end;
    while start > 0 && (b[start - 1].is_ascii_digit() || b[start - 1] == b'.' || b[start - 1] == b',') {
        start -= 1;
    }
    while start < end && !b[start].is_ascii_digit() {
        start += 1;
    }
    if start > 0 && (b[start - 1] == b'-' || b[start - 1] == b'+') {
        start -= 1;
    }
    (start < end).then(|| s[start..end].to_string())
}

/// Whether `written` is `value` rounded to the decimals it shows.
fn reads_as(written: &str, value: f64) -> bool {
    let plain = written.replace(',', "");
    let Ok(w) = plain.parse::<f64>() else { return false };
    let decimals = plain.split('.').nth(1).map_or(0, |d| d.len()) as i32;
    let half = 0.5 * 10f64.powi(-decimals);
    (w - value).abs() <= half * (1.0 + 1e-9)
}

/// What is wrong with the figures `text` quotes, against `values`.
fn mismatches(name: &str, text: &str, values: &HashMap<String, f64>) -> Vec<String> {
    let mut wrong = Vec::new();
    for q in quotes(text) {
        let at = format!("{name}:{}: {}", q.line, q.key);
        match (q.written, values.get(&q.key)) {
            (None, _) => wrong.push(format!("{at}: no number before the marker")),
            (Some(_), None) => wrong.push(format!("{at}: no such key in notes/results.csv")),
            (Some(w), Some(&v)) if !reads_as(&w, v) => {
                wrong.push(format!("{at}: written {w}, notes/results.csv has {v}"))
            }
            _ => {}
        }
    }
    wrong
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every Markdown file under notes/.
fn quoting_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e == "md") {
                out.push(p);
            }
        }
    }
    let mut files = vec![root().join("README.md")];
    walk(&root().join("notes"), &mut files);
    files
}

fn results() -> HashMap<String, f64> {
    let text = std::fs::read_to_string(root().join("notes/results.csv")).expect("notes/results.csv");
    read_results(&text).unwrap_or_else(|e| panic!("notes/results.csv: {e}"))
}

#[test]
fn every_quoted_figure_is_the_results_files() {
    let values = results();
    let mut wrong = Vec::new();
    let mut count = 0;
    for path in quoting_files() {
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.strip_prefix(root()).unwrap().display().to_string();
        count += quotes(&text).len();
        wrong.extend(mismatches(&name, &text, &values));
    }
    assert!(wrong.is_empty(), "figures that differ from notes/results.csv:\n{}", wrong.join("\n"));
    // README's headline figures are quoted, not restated.
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let keys: Vec<String> = quotes(&readme).into_iter().map(|q| q.key).collect();
    for key in ["default.wall_s", "default.rmse", "mitsuba.accepted", "tests.count"] {
        assert!(keys.iter().any(|k| k == key), "README.md does not quote {key}");
    }
    assert!(count >= 10, "only {count} quoted figures in README.md and notes/");
}

#[test]
fn the_results_file_names_how_each_figure_was_measured() {
    let text = std::fs::read_to_string(root().join("notes/results.csv")).unwrap();
    let values = read_results(&text).unwrap();
    for key in ["default.wall_s", "default.rmse", "raycast.renderer_ns", "tests.count", "mitsuba.accepted"] {
        assert!(values.contains_key(key), "notes/results.csv has no {key}");
    }
    assert!(values["default.wall_s"] > 0.0 && values["default.rmse"] > 0.0);
}

#[test]
fn a_figure_that_drifted_is_caught() {
    let values: HashMap<String, f64> =
        [("a".to_string(), 7.84), ("b".to_string(), 0.002014), ("c".to_string(), 28160.0), ("d".to_string(), -0.02)]
            .into_iter()
            .collect();
    let ok = "took **7.8 s**<!--r:a--> for 0.00201<!--r:b--> at 28,160<!--r:c--> spp, -0.02%<!--r:d-->";
    assert_eq!(mismatches("t", ok, &values), Vec::<String>::new());
    let drifted = "the default command: 8.37 s<!--r:a-->\nan RMSE of 0.0021<!--r:b-->";
    let wrong = mismatches("t", drifted, &values);
    assert_eq!(wrong.len(), 2, "{wrong:?}");
    assert!(wrong[0].contains("t:1: a: written 8.37"), "{wrong:?}");
    assert!(wrong[1].contains("t:2: b: written 0.0021"), "{wrong:?}");
    let unknown = mismatches("t", "9 ns<!--r:nope--> and <!--r:a-->", &values);
    assert!(unknown[0].contains("no such key"), "{unknown:?}");
    assert!(unknown[1].contains("no number before"), "{unknown:?}");
    // A number far from the marker is not taken for it.
    assert_eq!(number_before("7.8 seconds, quoted<!--r:a-->".split("<!--").next().unwrap()), None);
    assert!(reads_as("8", 7.84) && !reads_as("7", 7.84) && reads_as("-0.0", -0.02) && !reads_as("-0.03", -0.02));
}

#[test]
fn a_malformed_results_file_is_refused() {
    assert!(read_results("key,value\n").unwrap_err().contains("header"));
    let head = "key,value,unit,command,commit,machine,date\n";
    assert!(read_results(&format!("{head}a,x,s,c,1,m,d\n")).unwrap_err().contains("not a number"));
    assert!(read_results(&format!("{head}a,1,s,c,1,m\n")).unwrap_err().contains("fields"));
    assert!(read_results(&format!("{head}a,1,s,,1,m,d\n")).unwrap_err().contains("no command"));
    assert!(read_results(&format!("{head}a,1,s,c,1,m,d\na,2,s,c,1,m,d\n")).unwrap_err().contains("twice"));
    assert_eq!(read_results(&format!("{head}a,1.5,s,c,1,m,d\n")).unwrap()["a"], 1.5);
}
