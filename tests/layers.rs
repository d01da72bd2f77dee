//! The library's layers run one way: a module imports (`crate::…`) only
//! modules of its own layer or of the layers below, and no module
//! depends, through any chain of imports, on itself. Read from the
//! sources' `use crate::…` and `crate::…` paths (comments and test modules
//! left out), so an import that would close a cycle fails here, naming
//! the files that make it. A new top-level module must be given a layer.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom up: each top-level module of `src/lib.rs` in one.
const LAYERS: &[(&str, &[&str])] = &[
    (
        "foundations",
        &[
            "math",
            "error",
            "interrupt",
            "sampling",
            "optics",
            "filter",
            "film",
            "output",
            "metrics",
            "display",
            "progress",
            "stats",
            "suite",
        ],
    ),
    ("scene parts", &["shape", "texture", "material", "envmap", "light", "camera", "medium"]),
    ("accelerator", &["accel"]),
    ("scene", &["scene", "export"]),
    ("photon maps", &["photon"]),
    ("integrators", &["integrator"]),
    // `settings` is `render::settings`, named at the crate's top too.
    ("render", &["render", "settings", "memory", "provenance"]),
    ("commands", &["command"]),
];

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a source file: its test module and its comments left out.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// The top-level modules a file's code names as `crate::NAME`.
fn named(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let before = code[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let rest = &code[i + "crate::".len()..];
        let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
        if !name.is_empty() {
            out.insert(name);
        } else if let Some(group) = rest.strip_prefix('{') {
            // `use crate::{a::x, b};`
            for part in group.split('}').next().unwrap_or("").split(',') {
                let name: String = part.trim().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        }
    }
    out
}

/// module -> (module it imports -> the files that import it).
fn edges() -> BTreeMap<String, BTreeMap<String, BTreeSet<String>>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut edges: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for file in files {
        let rel = file.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        if rel.starts_with("bin/") || rel == "lib.rs" {
            continue;
        }
        let module = rel.split('/').next().unwrap().trim_end_matches(".rs").to_string();
        let entry = edges.entry(module.clone()).or_default();
        for target in named(&code(&std::fs::read_to_string(&file).unwrap())) {
            if target != module {
                entry.entry(target).or_default().insert(rel.clone());
            }
        }
    }
    edges
}

fn layer_of(module: &str) -> Option<(usize, &'static str)> {
    LAYERS.iter().enumerate().find(|(_, (_, members))| members.contains(&module)).map(|(i, (name, _))| (i, *name))
}

#[test]
fn every_module_imports_only_its_layer_and_those_below() {
    let mut wrong = Vec::new();
    for (module, targets) in edges() {
        let Some((from, from_name)) = layer_of(&module) else {
            wrong.push(format!("src/{module}: a module of no layer (give it one in tests/layers.rs)"));
            continue;
        };
        for (target, files) in targets {
            match layer_of(&target) {
                Some((to, to_name)) if to > from => wrong.push(format!(
                    "{module} ({from_name}) imports {target} ({to_name}, a layer above) in {}",
                    files.into_iter().collect::<Vec<_>>().join(", ")
                )),
                None => wrong.push(format!("{module} imports {target}, a module of no layer")),
                _ => {}
            }
        }
    }
    assert!(wrong.is_empty(), "layering broken:\n{}", wrong.join("\n"));
}

#[test]
fn no_module_depends_on_itself() {
    let edges = edges();
    // Tarjan's strongly connected components: any of more than one module
    // is a cycle.
    struct State<'a> {
        edges: &'a BTreeMap<String, BTreeMap<String, BTreeSet<String>>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        cycles: Vec<Vec<&'a str>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        for w in s.edges.get(v).into_iter().flat_map(|t| t.keys()) {
            if !s.index.contains_key(w.as_str()) {
                visit(s, w);
                let l = s.low[w.as_str()].min(s.low[v]);
                s.low.insert(v, l);
            } else if s.stack.contains(&w.as_str()) {
                let l = s.index[w.as_str()].min(s.low[v]);
                s.low.insert(v, l);
            }
        }
        if s.low[v] == s.index[v] {
            let at = s.stack.iter().rposition(|&x| x == v).unwrap();
            let component: Vec<&str> = s.stack.split_off(at);
            if component.len() > 1 {
                s.cycles.push(component);
            }
        }
    }
    let mut state =
        State { edges: &edges, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), cycles: Vec::new() };
    for v in edges.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(&mut state, v);
        }
    }
    let mut said = Vec::new();
    for cycle in &state.cycles {
        for a in cycle {
            for (b, files) in edges.get(*a).into_iter().flatten() {
                if cycle.contains(&b.as_str()) {
                    said.push(format!("{a} -> {b} ({})", files.iter().cloned().collect::<Vec<_>>().join(", ")));
                }
            }
        }
    }
    assert!(state.cycles.is_empty(), "import cycles {:?}:\n{}", state.cycles, said.join("\n"));
}

/// The reader of imports sees what it must: a grouped import, a path in
/// code, and not a comment or a test module.
#[test]
fn imports_are_read_from_code_only() {
    let text = "use crate::{math::Color, film};\n// crate::render is a comment\nfn f() { crate::scene::x(); }\n\
                #[cfg(test)]\nmod tests { use crate::command; }\n";
    let got: Vec<String> = named(&code(text)).into_iter().collect();
    assert_eq!(got, ["film", "math", "scene"]);
}
