//! The project's rule "no function over 150 lines", kept by a test.
//!
//! A small scan of every `.rs` file under `crate/src`, `crate/examples` and
//! `tests`:
//! comments, string and character literals are blanked out, then each
//! `fn NAME` is followed to the `{` that opens its body and the matching `}`
//! that closes it. A function's length is the number of lines from the line
//! holding `fn` to the line holding its closing brace, both included (the
//! same count an editor shows for the span). Nested functions and closures
//! count inside their parent and are also measured on their own.
//!
//! Exemptions are explicit:
//! - [`EXEMPT_FILES`]: the SIMD kernels, written as long straight-line
//!   intrinsic sequences on purpose.
//! - [`ALLOWED`]: functions known to be too long, waiting to be split. The
//!   list only shrinks: an entry whose function is now within the limit (or
//!   gone) fails the test too, so whoever splits a function removes its entry.
//!
//! Natively only: the wasm test run has no file system.
#![cfg(not(target_arch = "wasm32"))]

use std::path::{Path, PathBuf};

/// The longest a function may be, in lines.
const LIMIT: usize = 150;

/// Files whose functions are not measured, relative to the repository root.
const EXEMPT_FILES: [&str; 1] = [
    // The SIMD kernels, exempt by the project's rule: a kernel may be one
    // long intrinsic sequence. (None is over the limit today.)
    "crate/src/surf/simd.rs",
];

/// Functions over the limit that are waiting to be split: (file, function).
/// Remove an entry when its function is split; the test fails on a stale one.
const ALLOWED: [(&str, &str); 0] = [];

/// One measured function.
#[derive(Debug, Clone, PartialEq)]
struct Function {
    name: String,
    /// 1-based line of the `fn` keyword.
    line: usize,
    lines: usize,
}

/// The source with comments and the insides of string and character literals
/// replaced by spaces; newlines are kept so line numbers stay right.
fn blank_literals(src: &str) -> Vec<char> {
    let s: Vec<char> = src.chars().collect();
    let mut out = s.clone();
    let blank = |out: &mut Vec<char>, from: usize, to: usize| {
        for c in out.iter_mut().take(to.min(s.len())).skip(from) {
            if *c != '\n' {
                *c = ' ';
            }
        }
    };
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        let next = s.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            let end = s[i..]
                .iter()
                .position(|&c| c == '\n')
                .map_or(s.len(), |p| i + p);
            blank(&mut out, i, end);
            i = end;
        } else if c == '/' && next == Some('*') {
            let (mut depth, mut j) = (1, i + 2);
            while j < s.len() && depth > 0 {
                if s[j] == '/' && s.get(j + 1) == Some(&'*') {
                    depth += 1;
                    j += 2;
                } else if s[j] == '*' && s.get(j + 1) == Some(&'/') {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            blank(&mut out, i, j);
            i = j;
        } else if let Some(end) = raw_string_end(&s, i) {
            blank(&mut out, i, end);
            i = end;
        } else if c == '"' {
            let mut j = i + 1;
            while j < s.len() && s[j] != '"' {
                j += if s[j] == '\\' { 2 } else { 1 };
            }
            blank(&mut out, i, j + 1);
            i = j + 1;
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{7f}') or a lifetime ('a).
            if next == Some('\\') {
                let mut j = i + 2;
                while j < s.len() && s[j] != '\'' {
                    j += 1;
                }
                blank(&mut out, i, j + 1);
                i = j + 1;
            } else if s.get(i + 2) == Some(&'\'') {
                blank(&mut out, i, i + 3);
                i += 3;
            } else {
                i += 1;
            }
        } else if is_ident(c) {
            // Skip whole identifiers so a `b` or `r` inside one never starts a literal.
            while i < s.len() && is_ident(s[i]) {
                i += 1;
            }
            // A b"…" or b'…' prefix is skipped with the word; the literal
            // itself is handled on the next turn.
        } else {
            i += 1;
        }
    }
    out
}

/// The end (one past the closing `#`s) of a raw string `r#"…"#` / `br"…"` that
/// starts at `i`, if one does.
fn raw_string_end(s: &[char], i: usize) -> Option<usize> {
    if i > 0 && is_ident(s[i - 1]) {
        return None;
    }
    let mut j = i;
    if s.get(j) == Some(&'b') || s.get(j) == Some(&'c') {
        j += 1;
    }
    if s.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let hashes = s[j..].iter().take_while(|&&c| c == '#').count();
    j += hashes;
    if s.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < s.len() {
        if s[j] == '"'
            && s[j + 1..]
                .iter()
                .take(hashes)
                .filter(|&&c| c == '#')
                .count()
                == hashes
        {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(s.len())
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Every function with a body in `src`, with its length in lines.
fn functions(src: &str) -> Vec<Function> {
    let s = blank_literals(src);
    let line_of = |pos: usize| 1 + s[..pos].iter().filter(|&&c| c == '\n').count();
    let mut found = Vec::new();
    let mut i = 0;
    while i + 2 < s.len() {
        let keyword = s[i] == 'f'
            && s[i + 1] == 'n'
            && (i == 0 || !is_ident(s[i - 1]))
            && s[i + 2].is_whitespace();
        if !keyword {
            i += 1;
            continue;
        }
        let mut j = i + 2;
        while j < s.len() && s[j].is_whitespace() {
            j += 1;
        }
        let name: String = s[j..].iter().take_while(|&&c| is_ident(c)).collect();
        if name.is_empty() {
            i += 2;
            continue;
        }
        // The body opens at the first `{` outside brackets; a `;` first means
        // a declaration without a body (a trait method).
        let mut depth = 0i32;
        let mut k = j + name.len();
        let mut open = None;
        while k < s.len() {
            match s[k] {
                '(' | '[' | '<' => depth += 1,
                ')' | ']' => depth -= 1,
                '>' if s[k - 1] != '-' => depth -= 1,
                '{' if depth <= 0 => {
                    open = Some(k);
                    break;
                }
                ';' if depth <= 0 => break,
                _ => {}
            }
            k += 1;
        }
        if let Some(open) = open {
            let mut braces = 0;
            let mut close = open;
            for (at, &c) in s.iter().enumerate().skip(open) {
                if c == '{' {
                    braces += 1;
                } else if c == '}' {
                    braces -= 1;
                    if braces == 0 {
                        close = at;
                        break;
                    }
                }
            }
            let line = line_of(i);
            found.push(Function {
                name,
                line,
                lines: line_of(close) - line + 1,
            });
        }
        i = j;
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn scanner_measures_functions_from_fn_to_closing_brace() {
    let src = r##"
/// A doc comment mentioning fn fake() { with a brace.
pub fn short(x: u32) -> u32 {
    let s = "}}} fn in a string {";
    let c = '}';
    let r = r#"{ raw " }"#;
    x + 1
}

trait T {
    fn declared(&self) -> Vec<u8>;
    fn with_body<'a>(&'a self) -> impl Fn(u8) -> u8 + 'a
    where
        Self: Sized,
    {
        |b| b
    }
}
"##;
    let found = functions(src);
    let got: Vec<(&str, usize, usize)> = found
        .iter()
        .map(|f| (f.name.as_str(), f.line, f.lines))
        .collect();
    assert_eq!(got, [("short", 3, 6), ("with_body", 12, 6)]);
}

#[test]
fn no_function_is_over_150_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    rust_files(&root.join("crate/src"), &mut files);
    rust_files(&root.join("crate/examples"), &mut files);
    rust_files(&root.join("tests"), &mut files);
    let mut too_long = Vec::new();
    let mut allowed_seen = Vec::new();
    for path in &files {
        let rel = path
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if EXEMPT_FILES.contains(&rel.as_str()) {
            continue;
        }
        let src = std::fs::read_to_string(path).unwrap();
        for f in functions(&src).into_iter().filter(|f| f.lines > LIMIT) {
            if ALLOWED.contains(&(rel.as_str(), f.name.as_str())) {
                allowed_seen.push((rel.clone(), f.name.clone()));
            } else {
                too_long.push(format!(
                    "{rel}:{} fn {} is {} lines",
                    f.line, f.name, f.lines
                ));
            }
        }
    }
    let stale: Vec<String> = ALLOWED
        .iter()
        .filter(|(file, name)| !allowed_seen.iter().any(|(f, n)| f == file && n == name))
        .map(|(file, name)| format!("{file} fn {name}"))
        .collect();
    assert!(
        too_long.is_empty(),
        "functions over {LIMIT} lines (split them at their seams):\n  {}",
        too_long.join("\n  ")
    );
    assert!(
        stale.is_empty(),
        "allow-list entries now within {LIMIT} lines or gone; remove them from ALLOWED:\n  {}",
        stale.join("\n  ")
    );
}
