//! The layout of `src/` (STYLE.md point 17): the modules form a one-way pipeline without import cycles, every
//! file says what it holds in an opening `//!` comment, and files and functions stay small.
//!
//! The import check reads every file under `src/`, strips comments, string literals and `#[cfg(test)]` items,
//! and collects the paths each file uses: its `use` declarations and the `crate::`/`super::`/`self::` paths in
//! its code (and `vrw::` in the binary, `main.rs` and `cli/`). A path is resolved to the module of the file
//! that defines the item: through `mod.rs` (and `lib.rs`) re-exports where the item is re-exported by name,
//! otherwise to the module named. Each edge `A -> B` between modules is then an edge between the two siblings
//! under their deepest common directory: `gait::sweep -> walk::section` is the top-level edge `gait -> walk`,
//! `gait::sweep -> gait::continuation` an edge inside `src/gait/`. An edge from a file to its own directory
//! module (an item of `gait/mod.rs` not re-exported by name) or back is not an edge between siblings and is
//! ignored. Any cycle among the siblings of one directory (the top-level modules being the siblings of
//! `src/`, the binary one of them) fails the test, which prints it with the lines that make it.
//!
//! Tests are left out: a `#[cfg(test)]` module may use whatever it checks against.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Files over this many lines of code (outside `#[cfg(test)]`, not counting blank and comment-only lines)
/// fail: a file that grows past it holds more than one concern and is split.
const MAX_FILE_LINES: usize = 600;

/// Production functions over this many lines of code (from `fn` to its closing brace, not counting blank and
/// comment-only lines) fail: a function that grows past it does more than one step and is split.
const MAX_FUNCTION_LINES: usize = 80;

/// Whether a file over [`MAX_FILE_LINES`] fails the test or is only reported.
const ENFORCE_FILE_SIZE: bool = true;

/// The top-level modules in pipeline order (STYLE.md point 1): a module may import only those before it.
/// A top-level module not listed here is not checked for order (only for cycles).
const PIPELINE: &[&str] = &[
    "meter",
    "fmt",
    "integrate",
    "continuation",
    "params",
    "dynamics",
    "mechanism",
    "contact",
    "walk",
    "variational",
    "reference",
    "gait",
    "family",
    "study",
    "output",
    "app",
    BIN,
];

/// The first segment of the binary's module paths (`main.rs` is the binary's root, `cli/` its child).
const BIN: &str = "(bin)";

/// The library's crate name, as the binary spells paths into it.
const LIB_CRATE: &str = "vrw";

// ---------------------------------------------------------------------------------------------------------
// Tokens

/// A token of Rust source: an identifier or keyword, `::`, or one punctuation character; comments, string
/// and character literals and numbers are dropped.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    PathSep,
    Punct(char),
}

/// A token and the (1-based) line it starts on.
#[derive(Debug, Clone)]
struct Token {
    tok: Tok,
    line: usize,
}

/// Splits `src` into tokens.
fn tokenize(src: &str) -> Vec<Token> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut line = 1;
    let mut i = 0;
    let is_ident = |ch: char| ch == '_' || ch.is_alphanumeric();
    while i < c.len() {
        let ch = c[i];
        let next = c.get(i + 1).copied();
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && next == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if c[i] == '\n' {
                        line += 1;
                    }
                    i += 1;
                }
            }
        } else if ch == '"' {
            i = skip_string(&c, i + 1, 0, &mut line);
        } else if (ch == 'r' || ch == 'b' || ch == 'c')
            && raw_string_hashes(&c, i).is_some()
            && (i == 0 || !is_ident(c[i - 1]))
        {
            let (start, hashes) = raw_string_hashes(&c, i).unwrap();
            i = skip_string(&c, start, hashes, &mut line);
        } else if ch == '\'' {
            // A character literal ('a', '\n', '\u{..}') or a lifetime ('a).
            if next == Some('\\') {
                i += 2;
                while i < c.len() && c[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
                while i < c.len() && is_ident(c[i]) {
                    i += 1;
                }
            }
        } else if ch.is_ascii_digit() {
            while i < c.len()
                && (is_ident(c[i]) || c[i] == '.' && c.get(i + 1).is_some_and(char::is_ascii_digit))
            {
                i += 1;
            }
        } else if is_ident(ch) {
            let start = i;
            while i < c.len() && is_ident(c[i]) {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Ident(c[start..i].iter().collect()),
                line,
            });
        } else if ch == ':' && next == Some(':') {
            out.push(Token {
                tok: Tok::PathSep,
                line,
            });
            i += 2;
        } else {
            out.push(Token {
                tok: Tok::Punct(ch),
                line,
            });
            i += 1;
        }
    }
    out
}

/// If a raw or prefixed string literal (`r"`, `r#"`, `b"`, `br#"`, `c"`, ...) starts at `i`: the index just
/// past its opening quote and its number of `#`.
fn raw_string_hashes(c: &[char], i: usize) -> Option<(usize, usize)> {
    let mut j = i;
    if c[j] == 'b' || c[j] == 'c' {
        j += 1;
    }
    let raw = c.get(j) == Some(&'r');
    if raw {
        j += 1;
    }
    let mut hashes = 0;
    while raw && c.get(j) == Some(&'#') {
        hashes += 1;
        j += 1;
    }
    (j > i && c.get(j) == Some(&'"')).then_some((j + 1, hashes))
}

/// The index just past the string whose contents start at `i` (escapes count only without `#`).
fn skip_string(c: &[char], mut i: usize, hashes: usize, line: &mut usize) -> usize {
    while i < c.len() {
        match c[i] {
            '\\' if hashes == 0 => {
                if c.get(i + 1) == Some(&'\n') {
                    *line += 1;
                }
                i += 2;
            }
            '"' if (1..=hashes).all(|k| c.get(i + k) == Some(&'#')) => return i + 1 + hashes,
            ch => {
                if ch == '\n' {
                    *line += 1;
                }
                i += 1;
            }
        }
    }
    i
}

/// The tokens outside `#[cfg(test)]` items, and the line ranges of those items.
fn strip_tests(tokens: Vec<Token>) -> (Vec<Token>, Vec<(usize, usize)>) {
    let is = |t: Option<&Token>, tok: Tok| t.is_some_and(|t| t.tok == tok);
    let ident = |s: &str| Tok::Ident(s.to_string());
    let mut kept = Vec::new();
    let mut ranges = Vec::new();
    let mut i = 0;
    while i < tokens.len() {
        let attribute = [
            Tok::Punct('#'),
            Tok::Punct('['),
            ident("cfg"),
            Tok::Punct('('),
            ident("test"),
            Tok::Punct(')'),
            Tok::Punct(']'),
        ];
        let cfg_test = attribute
            .iter()
            .enumerate()
            .all(|(k, tok)| is(tokens.get(i + k), tok.clone()));
        if !cfg_test {
            kept.push(tokens[i].clone());
            i += 1;
            continue;
        }
        // The item: up to its `;`, or through the braces it opens first.
        let first = tokens[i].line;
        let mut j = i + attribute.len();
        let mut depth = 0usize;
        while j < tokens.len() {
            match tokens[j].tok {
                Tok::Punct('{') => depth += 1,
                Tok::Punct('}') => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                Tok::Punct(';') if depth == 0 => break,
                _ => {}
            }
            j += 1;
        }
        let last = tokens.get(j).map_or(usize::MAX, |t| t.line);
        ranges.push((first, last));
        i = j + 1;
    }
    (kept, ranges)
}

// ---------------------------------------------------------------------------------------------------------
// Paths

/// One path a file uses, as written, with the line it is on.
#[derive(Debug, Clone)]
struct UsedPath {
    segments: Vec<String>,
    line: usize,
    /// From a `use` declaration: the name it brings into scope (`None` for a glob), and whether it is `pub`.
    import: Option<Import>,
}

#[derive(Debug, Clone)]
struct Import {
    name: Option<String>,
}

/// The paths of the `use` tree at `tokens[*i..]`, prefixed by `prefix`.
fn parse_use_tree(tokens: &[Token], i: &mut usize, prefix: &[String], out: &mut Vec<UsedPath>) {
    let mut path = prefix.to_vec();
    let line = tokens.get(*i).map_or(0, |t| t.line);
    if matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::PathSep)) {
        *i += 1;
    }
    loop {
        match tokens.get(*i).map(|t| &t.tok) {
            Some(Tok::Ident(s)) => {
                path.push(s.clone());
                *i += 1;
                if matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::PathSep)) {
                    *i += 1;
                    continue;
                }
                // A leaf, possibly renamed.
                let mut name = path.last().cloned();
                if matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Ident(a)) if a == "as") {
                    *i += 1;
                    if let Some(Tok::Ident(alias)) = tokens.get(*i).map(|t| &t.tok) {
                        name = Some(alias.clone());
                        *i += 1;
                    }
                }
                // `use a::b::{self}` names the module `b`.
                if path.last().is_some_and(|s| s == "self") {
                    path.pop();
                    if name.as_deref() == Some("self") {
                        name = path.last().cloned();
                    }
                }
                out.push(UsedPath {
                    segments: path,
                    line,
                    import: Some(Import { name }),
                });
                return;
            }
            Some(Tok::Punct('*')) => {
                *i += 1;
                out.push(UsedPath {
                    segments: path,
                    line,
                    import: Some(Import { name: None }),
                });
                return;
            }
            Some(Tok::Punct('{')) => {
                *i += 1;
                loop {
                    match tokens.get(*i).map(|t| &t.tok) {
                        Some(Tok::Punct('}')) | None => {
                            *i += 1;
                            return;
                        }
                        Some(Tok::Punct(',')) => *i += 1,
                        _ => parse_use_tree(tokens, i, &path, out),
                    }
                }
            }
            _ => return,
        }
    }
}

/// Every path the tokens use: `use` declarations and paths in code that start with `crate`, `super`, `self`
/// or (in the binary) the library's name.
fn used_paths(tokens: &[Token], in_binary: bool) -> Vec<UsedPath> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < tokens.len() {
        let Tok::Ident(word) = &tokens[i].tok else {
            i += 1;
            continue;
        };
        let after_path_sep = i > 0 && tokens[i - 1].tok == Tok::PathSep;
        if word == "use" {
            i += 1;
            parse_use_tree(tokens, &mut i, &[], &mut out);
            continue;
        }
        let root =
            matches!(word.as_str(), "crate" | "super" | "self") || in_binary && word == LIB_CRATE;
        if root && !after_path_sep && tokens.get(i + 1).is_some_and(|t| t.tok == Tok::PathSep) {
            let line = tokens[i].line;
            let mut segments = vec![word.clone()];
            i += 1;
            while i + 1 < tokens.len() && tokens[i].tok == Tok::PathSep {
                let Tok::Ident(s) = &tokens[i + 1].tok else {
                    break;
                };
                segments.push(s.clone());
                i += 2;
            }
            out.push(UsedPath {
                segments,
                line,
                import: None,
            });
            continue;
        }
        i += 1;
    }
    out
}

// ---------------------------------------------------------------------------------------------------------
// Modules

/// A source file: its path under `src/` (with `/`), its module path, and its text.
#[derive(Debug, Clone)]
struct SourceFile {
    rel: String,
    module: Vec<String>,
    text: String,
}

/// The module path of the file at `rel` (relative to `src/`): `gait/sweep.rs` is `gait::sweep`, `gait/mod.rs`
/// is `gait`, `lib.rs` the crate root, `main.rs` the binary's root [`BIN`] and its siblings the binary's
/// modules.
fn module_of(rel: &str, binary_files: &BTreeSet<String>) -> Vec<String> {
    let stem = rel.trim_end_matches(".rs");
    let mut parts: Vec<String> = stem.split('/').map(str::to_string).collect();
    if binary_files.contains(rel) {
        if parts.last().is_some_and(|p| p == "main") {
            parts.pop();
        }
        parts.insert(0, BIN.to_string());
        return parts;
    }
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// An import edge between two modules and where it was seen.
#[derive(Debug, Clone)]
struct Evidence {
    file: String,
    line: usize,
    path: String,
}

/// What the checker found.
#[derive(Debug, Default)]
struct Layout {
    /// For each directory (module path of the directory; empty for `src/`), the edges between its children
    /// and where each was first seen.
    graphs: BTreeMap<Vec<String>, BTreeMap<(String, String), Evidence>>,
}

impl Layout {
    /// Reads the files and builds the graphs. `files` are `(path under src/, text)`; `main.rs` and the files
    /// it declares with `mod` beside it are the binary.
    fn new(files: &[(String, String)]) -> Layout {
        let mut binary_files = BTreeSet::new();
        if let Some((_, main)) = files.iter().find(|(rel, _)| rel == "main.rs") {
            binary_files.insert("main.rs".to_string());
            let tokens = tokenize(main);
            for w in tokens.windows(2) {
                if let (Tok::Ident(m), Tok::Ident(name)) = (&w[0].tok, &w[1].tok) {
                    if m == "mod" {
                        binary_files.insert(format!("{name}.rs"));
                    }
                }
            }
        }
        let test_only = test_only_files(files);
        let sources: Vec<SourceFile> = files
            .iter()
            .filter(|(rel, _)| !test_only.contains(rel))
            .map(|(rel, text)| SourceFile {
                rel: rel.clone(),
                module: module_of(rel, &binary_files),
                text: text.clone(),
            })
            .collect();
        let modules: BTreeSet<Vec<String>> = sources.iter().map(|f| f.module.clone()).collect();

        // Every file's paths, made absolute, and the names each module imports (what `super::Name` or
        // `crate::dir::Name` finds there).
        let mut uses: Vec<(usize, Vec<String>, UsedPath)> = Vec::new();
        let mut imports: BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>> = BTreeMap::new();
        let mut globs: BTreeMap<Vec<String>, Vec<Vec<String>>> = BTreeMap::new();
        for (index, f) in sources.iter().enumerate() {
            let in_binary = f.module.first().is_some_and(|m| m == BIN);
            let (tokens, _) = strip_tests(tokenize(&f.text));
            for used in used_paths(&tokens, in_binary) {
                let Some(abs) = absolute(&f.module, &used.segments, in_binary, &modules) else {
                    continue;
                };
                if let Some(import) = &used.import {
                    match &import.name {
                        Some(name) => {
                            imports
                                .entry(f.module.clone())
                                .or_default()
                                .insert(name.clone(), abs.clone());
                        }
                        None => globs.entry(f.module.clone()).or_default().push(abs.clone()),
                    }
                }
                uses.push((index, abs, used));
            }
        }

        let mut layout = Layout::default();
        for (index, abs, used) in uses {
            let f = &sources[index];
            let target = resolve(&abs, &modules, &imports, &globs);
            let from = &f.module;
            let common = from.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if common == from.len() || common == target.len() {
                // The same module, a child or the own parent (or an ancestor): not an edge between siblings.
                continue;
            }
            let dir = from[..common].to_vec();
            let edge = (from[common].clone(), target[common].clone());
            layout
                .graphs
                .entry(dir)
                .or_default()
                .entry(edge)
                .or_insert_with(|| Evidence {
                    file: format!("src/{}", f.rel),
                    line: used.line,
                    path: used.segments.join("::"),
                });
        }
        layout
    }

    /// Every cycle, one per strongly connected set of siblings, as lines of text (empty if there is none).
    fn cycles(&self) -> Vec<String> {
        let mut found = Vec::new();
        for (dir, edges) in &self.graphs {
            let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
            for (a, b) in edges.keys() {
                next.entry(a.as_str()).or_default().push(b.as_str());
            }
            let mut reported: BTreeSet<&str> = BTreeSet::new();
            for start in next.keys().copied() {
                if reported.contains(start) {
                    continue;
                }
                let Some(cycle) = shortest_cycle(start, &next) else {
                    continue;
                };
                reported.extend(cycle.iter().copied());
                let place = if dir.is_empty() {
                    "between the top-level modules".to_string()
                } else {
                    format!("inside src/{}/", dir.join("/"))
                };
                let mut text = format!("import cycle {place}: {}", cycle.join(" -> "));
                for w in cycle.windows(2) {
                    let e = &edges[&(w[0].to_string(), w[1].to_string())];
                    let _ = write!(
                        text,
                        "\n    {} -> {}: {}:{} uses {}",
                        w[0], w[1], e.file, e.line, e.path
                    );
                }
                found.push(text);
            }
        }
        found
    }

    /// The edges among the children of `dir`, as `a -> b` strings (for tests and reports).
    fn edges(&self, dir: &[&str]) -> Vec<String> {
        let dir: Vec<String> = dir.iter().map(|s| s.to_string()).collect();
        self.graphs
            .get(&dir)
            .map(|g| g.keys().map(|(a, b)| format!("{a} -> {b}")).collect())
            .unwrap_or_default()
    }
}

/// The absolute module path of `segments` used in `module`, or `None` for a path into another crate.
fn absolute(
    module: &[String],
    segments: &[String],
    in_binary: bool,
    modules: &BTreeSet<Vec<String>>,
) -> Option<Vec<String>> {
    let first = segments.first()?;
    let mut base: Vec<String>;
    let mut rest = segments;
    match first.as_str() {
        "crate" => {
            base = if in_binary {
                vec![BIN.to_string()]
            } else {
                Vec::new()
            };
            rest = &segments[1..];
        }
        LIB_CRATE if in_binary => {
            base = Vec::new();
            rest = &segments[1..];
        }
        "self" => {
            base = module.to_vec();
            rest = &segments[1..];
        }
        "super" => {
            base = module.to_vec();
            while rest.first().is_some_and(|s| s == "super") {
                base.pop()?;
                rest = &rest[1..];
            }
        }
        _ => {
            // A child module of this one (`pub use sweep::gait_rows;` in `gait/mod.rs`); else another crate.
            let mut child = module.to_vec();
            child.push(first.clone());
            if !modules.contains(&child) {
                return None;
            }
            base = module.to_vec();
        }
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

/// The module that defines what the absolute path `abs` names: the longest known module it starts with,
/// followed through the imports (re-exports) of that module by name.
fn resolve(
    abs: &[String],
    modules: &BTreeSet<Vec<String>>,
    imports: &BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>>,
    globs: &BTreeMap<Vec<String>, Vec<Vec<String>>>,
) -> Vec<String> {
    let longest = |path: &[String]| {
        (0..=path.len())
            .rev()
            .find(|&n| modules.contains(&path[..n].to_vec()))
            .unwrap_or(0)
    };
    let mut path = abs.to_vec();
    for _ in 0..32 {
        let n = longest(&path);
        let module = path[..n].to_vec();
        let Some(name) = path.get(n) else {
            return module;
        };
        let target = imports
            .get(&module)
            .and_then(|m| m.get(name))
            .cloned()
            .or_else(|| {
                // Through a glob re-export, if the glob's module has the name as a child module or import.
                globs.get(&module)?.iter().find_map(|g| {
                    let mut child = g.clone();
                    child.push(name.clone());
                    (modules.contains(&child)
                        || imports.get(g).is_some_and(|m| m.contains_key(name)))
                    .then_some(child)
                })
            });
        match target {
            Some(mut next) if next != path[..=n] => {
                next.extend(path[n + 1..].iter().cloned());
                path = next;
            }
            _ => return module,
        }
    }
    path[..longest(&path)].to_vec()
}

/// The shortest cycle through `start` (`start` first and last, in the direction of the edges), if any.
fn shortest_cycle<'a>(
    start: &'a str,
    next: &BTreeMap<&'a str, Vec<&'a str>>,
) -> Option<Vec<&'a str>> {
    let mut parent: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(node) = queue.pop_front() {
        for &n in next.get(node).map(Vec::as_slice).unwrap_or(&[]) {
            if n == start {
                let mut cycle = vec![start, node];
                while let Some(&p) = parent.get(cycle[cycle.len() - 1]) {
                    cycle.push(p);
                }
                cycle.reverse();
                return Some(cycle);
            }
            if n != start && !parent.contains_key(n) {
                parent.insert(n, node);
                queue.push_back(n);
            }
        }
    }
    None
}

// ---------------------------------------------------------------------------------------------------------
// The tree

/// Every `.rs` file under `src/`, as `(path under src/ with '/', text)`, sorted.
/// Files that are test code as a whole: declared `#[cfg(test)] mod name;` by their parent (shared test helpers),
/// so, like `#[cfg(test)]` items, they may use whatever they check against.
fn test_only_files(files: &[(String, String)]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (rel, text) in files {
        // The directory a file's `mod name;` children live in.
        let dir = match rel.rsplit_once('/') {
            Some((dir, "mod.rs")) => format!("{dir}/"),
            None if rel == "lib.rs" || rel == "main.rs" => String::new(),
            _ => format!("{}/", rel.trim_end_matches(".rs")),
        };
        let words: Vec<&str> = text.split_whitespace().collect();
        for w in words.windows(3) {
            if w[0] == "#[cfg(test)]" && w[1] == "mod" && w[2].ends_with(';') {
                let name = w[2].trim_end_matches(';');
                out.insert(format!("{dir}{name}.rs"));
                out.insert(format!("{dir}{name}/mod.rs"));
            }
        }
    }
    out
}

fn source_files() -> Vec<(String, String)> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
            .map(|e| e.expect("directory entry").path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, root, out);
            } else if path.extension().is_some_and(|x| x == "rs") {
                let rel = path.strip_prefix(root).expect("under src/");
                let rel = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
                    .join("/");
                let text = std::fs::read_to_string(&path)
                    .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
                out.push((rel, text));
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = Vec::new();
    walk(&root, &root, &mut out);
    out
}

/// Lines of code of `text` outside `#[cfg(test)]` items: not blank, not only a comment.
fn code_lines(text: &str) -> usize {
    let (_, tests) = strip_tests(tokenize(text));
    code_lines_in(text, 1..=usize::MAX, &tests)
}

/// Lines of code of `text` among the (1-based) lines `within`, outside the line ranges `tests`.
fn code_lines_in(
    text: &str,
    within: std::ops::RangeInclusive<usize>,
    tests: &[(usize, usize)],
) -> usize {
    let mut in_block_comment = false;
    text.lines()
        .enumerate()
        .filter(|(i, line)| {
            let n = i + 1;
            let t = line.trim();
            if in_block_comment {
                in_block_comment = !t.contains("*/");
                return false;
            }
            if t.starts_with("/*") {
                in_block_comment = !t.contains("*/");
                return false;
            }
            !t.is_empty()
                && !t.starts_with("//")
                && within.contains(&n)
                && !tests.iter().any(|&(a, b)| a <= n && n <= b)
        })
        .count()
}

/// The functions of `text` outside `#[cfg(test)]` items with their lines of code (from the line of `fn` to
/// that of its closing brace; a function nested in another counts in both): `(name, first line, lines)`.
fn function_lengths(text: &str) -> Vec<(String, usize, usize)> {
    let (tokens, tests) = strip_tests(tokenize(text));
    let mut out = Vec::new();
    for (i, t) in tokens.iter().enumerate() {
        let (Tok::Ident(kw), Some(Tok::Ident(name))) = (&t.tok, tokens.get(i + 1).map(|t| &t.tok))
        else {
            continue;
        };
        if kw != "fn" {
            continue;
        }
        // The body: the first `{` before a `;` (a declaration without a body has none), through its match.
        let mut depth = 0usize;
        let mut end = None;
        for u in &tokens[i + 2..] {
            match u.tok {
                Tok::Punct(';') if depth == 0 => break,
                Tok::Punct('{') => depth += 1,
                Tok::Punct('}') => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(u.line);
                        break;
                    }
                }
                _ => {}
            }
        }
        if let Some(last) = end {
            out.push((
                name.clone(),
                t.line,
                code_lines_in(text, t.line..=last, &tests),
            ));
        }
    }
    out
}

#[test]
fn src_has_no_import_cycles() {
    let layout = Layout::new(&source_files());
    let top = layout.edges(&[]);
    assert!(
        top.iter().any(|e| e == "gait -> walk"),
        "the checker sees no edge gait -> walk; does it read src/? edges: {top:?}"
    );
    // The graphs, for `cargo test --test layout -- --nocapture`.
    for (dir, edges) in &layout.graphs {
        let dir = if dir.is_empty() {
            "src".to_string()
        } else {
            format!("src/{}", dir.join("/"))
        };
        let edges: Vec<String> = edges.keys().map(|(a, b)| format!("{a} -> {b}")).collect();
        println!("{dir}: {}", edges.join(", "));
    }
    let cycles = layout.cycles();
    for c in &cycles {
        println!("{c}");
    }
    assert!(
        cycles.is_empty(),
        "{} import cycle(s) under src/:\n{}",
        cycles.len(),
        cycles.join("\n")
    );
}

#[test]
fn top_level_modules_follow_the_pipeline() {
    let layout = Layout::new(&source_files());
    let rank = |m: &str| PIPELINE.iter().position(|p| *p == m);
    let backward: Vec<String> = layout
        .graphs
        .get(&Vec::new())
        .into_iter()
        .flatten()
        .filter(|((a, b), _)| matches!((rank(a), rank(b)), (Some(i), Some(j)) if j >= i))
        .map(|((a, b), e)| format!("{a} -> {b} ({}:{} uses {})", e.file, e.line, e.path))
        .collect();
    assert!(
        backward.is_empty(),
        "imports against the pipeline order {PIPELINE:?}:\n  {}",
        backward.join("\n  ")
    );
}

#[test]
fn every_source_file_opens_with_a_doc_comment() {
    let missing: Vec<String> = source_files()
        .into_iter()
        .filter(|(_, text)| !text.starts_with("//!"))
        .map(|(rel, _)| format!("src/{rel}"))
        .collect();
    assert!(
        missing.is_empty(),
        "files that do not open with a `//!` comment saying what they hold: {missing:?}"
    );
}

#[test]
fn source_files_are_small() {
    let big: Vec<String> = source_files()
        .iter()
        .map(|(rel, text)| (rel, code_lines(text)))
        .filter(|&(_, n)| n > MAX_FILE_LINES)
        .map(|(rel, n)| format!("src/{rel}: {n} lines of code"))
        .collect();
    if !big.is_empty() {
        println!(
            "files over {MAX_FILE_LINES} lines of code outside #[cfg(test)]{}:\n  {}",
            if ENFORCE_FILE_SIZE {
                ""
            } else {
                " (reported, not enforced)"
            },
            big.join("\n  ")
        );
    }
    assert!(
        !ENFORCE_FILE_SIZE || big.is_empty(),
        "files over {MAX_FILE_LINES} lines of code outside #[cfg(test)]: {big:?}"
    );
}

#[test]
fn production_functions_are_short() {
    let files = source_files();
    let test_only = test_only_files(&files);
    let long: Vec<String> = files
        .iter()
        .filter(|(rel, _)| !test_only.contains(rel))
        .flat_map(|(rel, text)| {
            function_lengths(text)
                .into_iter()
                .filter(|&(_, _, n)| n > MAX_FUNCTION_LINES)
                .map(move |(name, line, n)| format!("src/{rel}:{line}: {name}: {n} lines of code"))
        })
        .collect();
    assert!(
        long.is_empty(),
        "production functions over {MAX_FUNCTION_LINES} lines of code:\n  {}",
        long.join("\n  ")
    );
}

/// The wheel's own names: its coordinate count and indices, its legs. The engine is to take any planar walker
/// through `mechanism::Mechanism` (docs/model.md section 9), after which none of these is left in the layers
/// above the wheel's model (`src/dynamics.rs`, `src/mechanism/wheel.rs`).
const WHEEL_NAMES: &[&str] = &["NQ", "L1", "L2", "L3", "THETA", "LegIndex", "Leg"];

/// The directories that are to take any walker, and the most uses of [`WHEEL_NAMES`] they hold today: the
/// count may only fall (lower it as the walk, the contact solves and the derivatives move onto the interface).
const WHEEL_NAMES_LEFT: &[(&str, usize)] = &[
    ("mechanism/", 0),
    ("contact/", 39),
    ("walk/", 60),
    ("variational/", 58),
    ("gait/", 5),
    ("family/", 0),
    ("study/", 5),
    ("output/", 3),
    ("app/", 1),
];

/// Uses of [`WHEEL_NAMES`] in the production code of the files under `dir` (of `src/`), `mechanism/wheel.rs`
/// (the wheel behind the interface) left out, and where they are.
fn wheel_names_in(files: &[(String, String)], dir: &str) -> (usize, Vec<String>) {
    let mut count = 0;
    let mut places = Vec::new();
    for (rel, text) in files.iter().filter(|(rel, _)| rel.starts_with(dir)) {
        if rel == "mechanism/wheel.rs" {
            continue;
        }
        let (tokens, _) = strip_tests(tokenize(text));
        for t in &tokens {
            if matches!(&t.tok, Tok::Ident(name) if WHEEL_NAMES.contains(&name.as_str())) {
                count += 1;
                places.push(format!("src/{rel}:{}", t.line));
            }
        }
    }
    (count, places)
}

#[test]
fn the_engine_holds_no_more_of_the_wheel_than_before() {
    let files = source_files();
    let mut grown = Vec::new();
    for &(dir, most) in WHEEL_NAMES_LEFT {
        let (count, places) = wheel_names_in(&files, dir);
        println!("src/{dir}: {count} uses of the wheel's names (at most {most})");
        if count > most {
            grown.push(format!(
                "src/{dir}: {count} uses of {WHEEL_NAMES:?}, more than {most}: {}",
                places.join(", ")
            ));
        }
    }
    assert!(grown.is_empty(), "{}", grown.join("\n"));
}

#[test]
fn a_long_function_is_measured_without_blank_lines_comments_and_tests() {
    let body = "    let x = 1;\n\n    // a comment\n".repeat(3);
    let text = format!(
        "//! A.\nfn f() {{\n{body}}}\ntrait T {{\n    fn g(&self);\n}}\n#[cfg(test)]\nfn h() {{\n{body}}}\n"
    );
    let lengths = function_lengths(&text);
    // `f`: its first and last line and the three `let` lines; `g` has no body; `h` is a test item.
    assert_eq!(lengths, vec![("f".to_string(), 2, 5)]);
}

// ---------------------------------------------------------------------------------------------------------
// The checker on small made-up trees

fn tree(files: &[(&str, &str)]) -> Layout {
    let files: Vec<(String, String)> = files
        .iter()
        .map(|(rel, text)| (rel.to_string(), text.to_string()))
        .collect();
    Layout::new(&files)
}

#[test]
fn a_cycle_between_top_level_modules_is_found() {
    let layout = tree(&[
        ("lib.rs", "//! Root.\npub mod a;\npub mod b;\npub mod c;\n"),
        ("a.rs", "//! A.\nuse crate::b::Thing;\npub struct A;\n"),
        (
            "b.rs",
            "//! B.\npub struct Thing;\nfn f() { let _ = crate::c::g(); }\n",
        ),
        (
            "c.rs",
            "//! C.\npub fn g() -> crate::a::A { crate::a::A }\n",
        ),
    ]);
    let cycles = layout.cycles();
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert!(
        cycles[0].starts_with("import cycle between the top-level modules: a -> b -> c -> a"),
        "{}",
        cycles[0]
    );
    assert!(
        cycles[0].contains("src/b.rs:3 uses crate::c::g"),
        "{}",
        cycles[0]
    );
}

#[test]
fn a_cycle_between_siblings_through_a_re_export_is_found() {
    // `y` uses `Foo` through `d/mod.rs`, which re-exports it from `x`; `x` uses `y`.
    let layout = tree(&[
        ("lib.rs", "//! Root.\npub mod d;\n"),
        (
            "d/mod.rs",
            "//! D.\npub mod x;\npub mod y;\npub use x::Foo;\n",
        ),
        (
            "d/x.rs",
            "//! X.\nuse super::y::{bar, Baz as Quux};\npub struct Foo;\n",
        ),
        (
            "d/y.rs",
            "//! Y.\nuse crate::d::Foo;\npub fn bar() {}\npub struct Baz;\n",
        ),
    ]);
    assert_eq!(layout.edges(&["d"]), ["x -> y", "y -> x"]);
    let cycles = layout.cycles();
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert!(
        cycles[0].starts_with("import cycle inside src/d/: x -> y -> x"),
        "{}",
        cycles[0]
    );
}

#[test]
fn comments_strings_tests_and_the_own_parent_make_no_edge() {
    let layout = tree(&[
        ("lib.rs", "//! Root.\npub mod d;\npub mod e;\n"),
        (
            "d/mod.rs",
            "//! D, see [`crate::e::E`].\npub mod x;\npub mod y;\nuse crate::e::E;\npub struct Shared;\n",
        ),
        (
            "d/x.rs",
            "//! X.\nuse super::Shared;\n/* crate::d::y::bar */\nconst S: &str = \"super::y::bar\";\n\
             const R: &str = r#\"crate::d::y \"#;\n#[cfg(test)]\nmod tests {\n    use crate::d::y::bar;\n}\n",
        ),
        ("d/y.rs", "//! Y.\nuse super::x;\npub fn bar() {}\n"),
        ("e.rs", "//! E.\npub struct E;\n"),
    ]);
    assert_eq!(layout.edges(&["d"]), ["y -> x"]);
    assert_eq!(layout.edges(&[]), ["d -> e"]);
    assert!(layout.cycles().is_empty());
}

#[test]
fn the_binary_is_a_top_level_module_of_its_own() {
    let layout = tree(&[
        ("lib.rs", "//! Root.\npub mod a;\n"),
        ("a.rs", "//! A.\npub fn run() {}\n"),
        (
            "main.rs",
            "//! Main.\nmod cli;\nfn main() { cli::run(); }\n",
        ),
        (
            "cli.rs",
            "//! Cli.\nuse vrw::a;\npub fn run() { a::run(); crate::cli::run(); }\n",
        ),
    ]);
    assert_eq!(layout.edges(&[]), [format!("{BIN} -> a")]);
    assert!(layout.cycles().is_empty());
}

#[test]
fn a_test_only_file_makes_no_edge() {
    let layout = tree(&[
        ("lib.rs", "//! L.\npub mod a;\npub mod b;\n"),
        (
            "a/mod.rs",
            "//! A.\n#[cfg(test)]\nmod helpers;\npub fn f() {}\n",
        ),
        ("a/helpers.rs", "//! Test helpers.\nuse crate::b::g;\n"),
        ("b.rs", "//! B.\nuse crate::a::f;\npub fn g() {}\n"),
    ]);
    assert!(layout.cycles().is_empty(), "{:?}", layout.cycles());
}

#[test]
fn code_lines_leave_out_tests_comments_and_blanks() {
    let text = "//! Doc.\n\nfn a() {}\n// note\nfn b() {\n}\n#[cfg(test)]\nmod tests {\n    fn t() {}\n}\n";
    assert_eq!(code_lines(text), 3);
}
