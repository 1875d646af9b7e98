//! # Reading SQLite 3 files, tables only, read-only
//!
//! rosbag2's default storage until ROS 2 Iron is an SQLite 3 database (a
//! `.db3` file). This module reads the parts of the SQLite file format a
//! recording needs, written after the format's own specification, "Database
//! File Format" (<https://www.sqlite.org/fileformat2.html>; the section
//! numbers below are that document's). No SQL is run: a table is read whole,
//! row by row, in rowid order.
//!
//! ## Pages and the header (§1.2–1.3)
//!
//! The file is a run of equal **pages**, numbered from 1. The first 100
//! bytes of page 1 are the database header: the magic string
//! `SQLite format 3\0`, the page size (a big-endian `u16` at byte 16, a power
//! of two from 512 to 32768, or 1 meaning 65536), the file format write and
//! read versions (bytes 18 and 19: 1 for a rollback journal, 2 for a
//! write-ahead log), the bytes each page reserves at its end for extensions
//! (byte 20; the rest is the page's **usable size** U), the database size in
//! pages (byte 28, trusted only when the change counter at byte 24 equals
//! the "version-valid-for" number at byte 92; otherwise the file's length
//! says it) and the text encoding (byte 56: 1 is UTF-8, the only one read
//! here; UTF-16 databases are refused with a clear error).
//!
//! ## Table b-trees (§1.6)
//!
//! A table is a **b-tree** keyed by the 64-bit rowid; its root page number is
//! in the schema. A page starts (after the 100-byte header on page 1) with
//! an 8-byte leaf or 12-byte interior page header: the page type (`0x0D` a
//! table leaf, `0x05` a table interior page), the number of cells, and on
//! interior pages the right-most child. An array of 2-byte cell offsets
//! follows, in key order. An interior cell is a 4-byte left child and a
//! varint key; every row under the left child has a rowid ≤ the key, and
//! the right-most child holds the rest. A leaf cell is a varint payload
//! size P, a varint rowid, and the payload. Reading the children left to
//! right, depth first, gives the rows in rowid order.
//!
//! A **varint** is 1 to 9 bytes, big-endian, 7 bits a byte with the high bit
//! meaning "more follows", except that a ninth byte gives all 8 bits.
//!
//! ## Overflow pages (§1.7)
//!
//! A payload that does not fit its leaf keeps its first bytes in the cell and
//! the rest in a chain of **overflow pages**, each a 4-byte next-page number
//! (0 at the end) and U − 4 bytes of payload. With X = U − 35,
//! M = ((U − 12) · 32 / 255) − 23 and K = M + ((P − M) mod (U − 4)), a leaf
//! keeps all P bytes when P ≤ X, else K bytes when K ≤ X, else M bytes,
//! followed by the first overflow page's number. A LaserScan of 1.5 to 3 KB
//! in a rosbag2 of 1 KB or 2 KB pages, or any larger message in 4 KB pages,
//! takes this path.
//!
//! ## Records (§2.1)
//!
//! A payload is a **record**: a varint header length (itself included), one
//! varint **serial type** per column, then the values. Serial types: 0 NULL;
//! 1, 2, 3, 4, 5, 6 a big-endian two's-complement integer of 1, 2, 3, 4, 6
//! or 8 bytes; 7 a big-endian IEEE double; 8 and 9 the integers 0 and 1;
//! N ≥ 12 even a blob of (N − 12) / 2 bytes; N ≥ 13 odd a text of
//! (N − 13) / 2 bytes. A record may hold fewer values than the table has
//! columns (columns added later): the missing ones read as NULL here. A
//! column declared `INTEGER PRIMARY KEY` is the rowid itself: the record
//! holds NULL for it, and [`Row::values`] puts the rowid there instead.
//!
//! ## The schema (§2.6)
//!
//! Page 1 is the root of `sqlite_schema`, a table of
//! `(type, name, tbl_name, rootpage, sql)`. Each table's column names, and
//! which column (if any) aliases the rowid, come from its `CREATE TABLE`
//! text, read by a small tokenizer ([`Table::from_sql`]). `WITHOUT ROWID`
//! tables are stored as index b-trees and are not read; generated columns
//! are not handled (rosbag2 uses neither).
//!
//! ## The write-ahead log (§4)
//!
//! A database in WAL mode (bytes 18 and 19 equal to 2) keeps its newest
//! pages in a separate `-wal` file until a checkpoint copies them back, and
//! rosbag2 killed in mid-recording leaves its last messages only there. The
//! file opens without its WAL (as it was at the last checkpoint); given the
//! WAL too ([`Database::open`]), its committed pages are read in place of
//! the file's. The WAL is a 32-byte header (magic `0x377f0682` or
//! `0x377f0683`, format version 3007000, page size, checkpoint sequence, two
//! salts, a checksum of the first 24 bytes) and frames of a 24-byte header
//! (page number; for a commit frame the database size in pages after the
//! commit, else 0; the two salts; a cumulative checksum) and one page. A
//! frame is valid when its salts match the header's and its checksum
//! matches the one computed over the WAL header's first 24 bytes and every
//! frame up to it (first 8 header bytes and the page); the checksum adds
//! 32-bit words in pairs, `s0 += x(i) + s1; s1 += x(i+1) + s0`, the words
//! big-endian when the magic ends in 3 and little-endian when it ends in 2.
//! Reading stops at the first invalid frame; the pages of every valid frame
//! up to the last valid commit frame count, the latest copy of a page
//! winning, and frames after that commit (a transaction never finished) do
//! not ([`WalSummary`] says how many there were). A WAL with a broken header
//! is ignored, as SQLite ignores it.
//!
//! ## A damaged file
//!
//! Every page number is checked against the database size, every cell and
//! every value against its page's or record's end, and each page may be
//! visited once per table read, so a cycle in a b-tree or an overflow chain
//! is an error, not an endless loop; an overflow chain is also checked
//! against its expected length before anything is allocated. Errors name
//! the page ([`SqliteError`]).

use std::borrow::Cow;
use std::collections::HashMap;
use std::fmt;

/// The 16 bytes every SQLite 3 database starts with.
pub const MAGIC: &[u8; 16] = b"SQLite format 3\0";

/// What is wrong, and on which page when a page is at fault.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SqliteError {
    /// The page at fault; `None` for the header or the file as a whole.
    pub page: Option<u32>,
    pub message: String,
}

impl SqliteError {
    fn file(message: impl Into<String>) -> SqliteError {
        SqliteError {
            page: None,
            message: message.into(),
        }
    }

    fn page(page: u32, message: impl Into<String>) -> SqliteError {
        SqliteError {
            page: Some(page),
            message: message.into(),
        }
    }
}

impl fmt::Display for SqliteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.page {
            Some(p) => write!(f, "page {p}: {}", self.message),
            None => write!(f, "{}", self.message),
        }
    }
}

impl std::error::Error for SqliteError {}

/// The fields of the database header the reader uses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DbHeader {
    /// Bytes per page (512 to 65536).
    pub page_size: usize,
    /// Bytes at the end of each page reserved for extensions.
    pub reserved: usize,
    /// File format write and read versions: 1 rollback journal, 2 WAL.
    pub write_version: u8,
    pub read_version: u8,
    /// Pages in the database, after the WAL's last commit if a WAL was read.
    pub page_count: u32,
    /// 1 for UTF-8 (the only one read).
    pub text_encoding: u32,
}

impl DbHeader {
    /// A page's usable size U: the page size less the reserved bytes.
    pub fn usable_size(&self) -> usize {
        self.page_size - self.reserved
    }

    /// True when the file says it is in WAL mode.
    pub fn wal_mode(&self) -> bool {
        self.write_version == 2 || self.read_version == 2
    }
}

/// What a WAL file held and what of it was applied.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WalSummary {
    /// Whole frames in the file.
    pub frames: usize,
    /// Frames up to and including the last valid commit frame: applied.
    pub committed_frames: usize,
    /// Commit frames among them: transactions applied.
    pub transactions: usize,
    /// Valid frames after the last commit: a transaction that never
    /// finished, not part of the database.
    pub uncommitted_frames: usize,
    /// Frames after the first invalid one (a bad checksum or salt: left
    /// over from before a checkpoint, or written partly).
    pub invalid_frames: usize,
    /// Why the whole WAL was ignored (a damaged header), if it was.
    pub ignored: Option<String>,
}

/// A column's value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value<'a> {
    Null,
    Integer(i64),
    Real(f64),
    Text(Cow<'a, str>),
    Blob(Cow<'a, [u8]>),
}

impl<'a> Value<'a> {
    pub fn as_integer(&self) -> Option<i64> {
        match self {
            Value::Integer(v) => Some(*v),
            _ => None,
        }
    }

    pub fn as_text(&self) -> Option<&str> {
        match self {
            Value::Text(t) => Some(t),
            _ => None,
        }
    }

    /// A blob's bytes, or a text's.
    pub fn as_bytes(&self) -> Option<&[u8]> {
        match self {
            Value::Blob(b) => Some(b),
            Value::Text(t) => Some(t.as_bytes()),
            _ => None,
        }
    }

    /// The same value owning its bytes.
    pub fn into_owned(self) -> Value<'static> {
        match self {
            Value::Null => Value::Null,
            Value::Integer(v) => Value::Integer(v),
            Value::Real(v) => Value::Real(v),
            Value::Text(t) => Value::Text(Cow::Owned(t.into_owned())),
            Value::Blob(b) => Value::Blob(Cow::Owned(b.into_owned())),
        }
    }

    /// What the value is, for error messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Null => "NULL",
            Value::Integer(_) => "an integer",
            Value::Real(_) => "a real",
            Value::Text(_) => "a text",
            Value::Blob(_) => "a blob",
        }
    }
}

/// One row of a table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row<'a> {
    pub rowid: i64,
    /// The leaf page the row's cell is on.
    pub page: u32,
    /// The values in column order, the rowid alias column holding the rowid.
    pub values: Vec<Value<'a>>,
}

impl<'a> Row<'a> {
    /// Column `i`'s value; NULL when the record is shorter.
    pub fn get(&self, i: usize) -> &Value<'a> {
        self.values.get(i).unwrap_or(&Value::Null)
    }

    /// Takes column `i`'s value out of the row (leaving NULL).
    pub fn take(&mut self, i: usize) -> Value<'a> {
        match self.values.get_mut(i) {
            Some(v) => std::mem::replace(v, Value::Null),
            None => Value::Null,
        }
    }
}

/// A table of the schema.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Table {
    pub name: String,
    pub root_page: u32,
    /// Column names in declaration order.
    pub columns: Vec<String>,
    /// The `INTEGER PRIMARY KEY` column, which is the rowid.
    pub rowid_alias: Option<usize>,
    /// Per column: REAL affinity (a declared type containing `REAL`,
    /// `FLOA` or `DOUB` and no `INT`), whose whole numbers SQLite may store
    /// as integers; they are read back as reals.
    pub real_affinity: Vec<bool>,
    /// Stored as an index b-tree: not readable here.
    pub without_rowid: bool,
}

impl Table {
    /// The index of a column, by name (ASCII case-insensitive, as SQL).
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))
    }

    /// A table described by its `CREATE TABLE` statement.
    pub fn from_sql(name: &str, root_page: u32, sql: &str) -> Result<Table, String> {
        let tokens = tokenize(sql)?;
        let open = tokens
            .iter()
            .position(|t| *t == Token::Punct('('))
            .ok_or_else(|| format!("table {name}: no column list in {sql:?}"))?;
        let mut defs: Vec<Vec<Token>> = vec![Vec::new()];
        let mut depth = 0usize;
        let mut close = None;
        for (i, t) in tokens.iter().enumerate().skip(open + 1) {
            match t {
                Token::Punct('(') => depth += 1,
                Token::Punct(')') if depth == 0 => {
                    close = Some(i);
                    break;
                }
                Token::Punct(')') => depth -= 1,
                Token::Punct(',') if depth == 0 => {
                    defs.push(Vec::new());
                    continue;
                }
                _ => {}
            }
            if let Some(d) = defs.last_mut() {
                d.push(t.clone());
            }
        }
        let close = close.ok_or_else(|| format!("table {name}: unclosed column list"))?;
        let rest = tokens.get(close + 1..).unwrap_or(&[]);
        let without_rowid = rest
            .windows(2)
            .any(|w| w[0].is_word("WITHOUT") && w[1].is_word("ROWID"));
        let mut table = Table {
            name: name.to_string(),
            root_page,
            columns: Vec::new(),
            rowid_alias: None,
            real_affinity: Vec::new(),
            without_rowid,
        };
        let mut integer_columns = Vec::new();
        let mut pk_constraint = None;
        for def in &defs {
            let Some(first) = def.first() else {
                return Err(format!("table {name}: an empty column definition"));
            };
            if ["CONSTRAINT", "PRIMARY", "UNIQUE", "CHECK", "FOREIGN"]
                .iter()
                .any(|k| first.is_word(k))
            {
                if let Some(col) = primary_key_constraint(def) {
                    pk_constraint = Some(col);
                }
                continue;
            }
            let index = table.columns.len();
            table.columns.push(first.text().to_string());
            let (is_integer, is_pk, is_real) = column_constraints(def);
            table.real_affinity.push(is_real);
            if is_integer {
                integer_columns.push(index);
                if is_pk {
                    table.rowid_alias = Some(index);
                }
            }
        }
        if let Some(col) = pk_constraint {
            if let Some(i) = table.column(&col) {
                if integer_columns.contains(&i) {
                    table.rowid_alias = Some(i);
                }
            }
        }
        if table.without_rowid {
            table.rowid_alias = None;
        }
        Ok(table)
    }
}

/// A token of SQL text.
#[derive(Clone, Debug, PartialEq)]
enum Token {
    /// A bare word (keyword, name, number).
    Word(String),
    /// A quoted name (`"x"`, `` `x` ``, `[x]`) or a string literal (`'x'`).
    Quoted(String),
    Punct(char),
}

impl Token {
    fn is_word(&self, keyword: &str) -> bool {
        matches!(self, Token::Word(w) if w.eq_ignore_ascii_case(keyword))
    }

    fn text(&self) -> &str {
        match self {
            Token::Word(w) | Token::Quoted(w) => w,
            Token::Punct(_) => "",
        }
    }
}

/// Splits SQL into words, quoted names and punctuation, skipping white
/// space and `--` / `/* */` comments.
fn tokenize(sql: &str) -> Result<Vec<Token>, String> {
    let chars: Vec<char> = sql.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while let Some(&c) = chars.get(i) {
        let next = chars.get(i + 1).copied();
        if c.is_whitespace() {
            i += 1;
        } else if c == '-' && next == Some('-') {
            while chars.get(i).is_some_and(|&c| c != '\n') {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            i += 2;
            while i < chars.len() && !(chars[i] == '*' && chars.get(i + 1) == Some(&'/')) {
                i += 1;
            }
            i += 2;
        } else if let Some(close) = match c {
            '"' => Some('"'),
            '`' => Some('`'),
            '\'' => Some('\''),
            '[' => Some(']'),
            _ => None,
        } {
            let mut text = String::new();
            i += 1;
            loop {
                match chars.get(i) {
                    None => return Err(format!("unclosed quote {c} in {sql:?}")),
                    Some(&d) if d == close => {
                        // A doubled quote is the quote itself (not for `[]`).
                        if close != ']' && chars.get(i + 1) == Some(&close) {
                            text.push(close);
                            i += 2;
                        } else {
                            i += 1;
                            break;
                        }
                    }
                    Some(&d) => {
                        text.push(d);
                        i += 1;
                    }
                }
            }
            tokens.push(Token::Quoted(text));
        } else if c.is_alphanumeric() || c == '_' || c == '$' {
            let start = i;
            while chars
                .get(i)
                .is_some_and(|&c| c.is_alphanumeric() || c == '_' || c == '$')
            {
                i += 1;
            }
            tokens.push(Token::Word(chars[start..i].iter().collect()));
        } else {
            tokens.push(Token::Punct(c));
            i += 1;
        }
    }
    Ok(tokens)
}

/// A column definition's type is exactly `INTEGER`; it says `PRIMARY KEY`
/// (not `PRIMARY KEY DESC`, which by SQLite's old quirk does not alias the
/// rowid); its type has REAL affinity (§3.1 of "Datatypes in SQLite":
/// `INT` first, then `CHAR`/`CLOB`/`TEXT`, then `BLOB`, then
/// `REAL`/`FLOA`/`DOUB`).
fn column_constraints(def: &[Token]) -> (bool, bool, bool) {
    let type_end = def
        .iter()
        .skip(1)
        .position(|t| {
            !matches!(t, Token::Word(_))
                || [
                    "CONSTRAINT",
                    "PRIMARY",
                    "NOT",
                    "NULL",
                    "UNIQUE",
                    "CHECK",
                    "DEFAULT",
                    "COLLATE",
                    "REFERENCES",
                    "GENERATED",
                    "AS",
                ]
                .iter()
                .any(|k| t.is_word(k))
        })
        .map_or(def.len(), |p| p + 1);
    let type_words = def.get(1..type_end).unwrap_or(&[]);
    let is_integer = type_words.len() == 1 && type_words[0].is_word("INTEGER");
    let declared = type_words
        .iter()
        .map(|t| t.text().to_ascii_uppercase())
        .collect::<Vec<_>>()
        .join(" ");
    let has = |k: &str| declared.contains(k);
    let is_real = !has("INT")
        && !has("CHAR")
        && !has("CLOB")
        && !has("TEXT")
        && !has("BLOB")
        && (has("REAL") || has("FLOA") || has("DOUB"));
    let is_pk = def.windows(2).enumerate().any(|(i, w)| {
        w[0].is_word("PRIMARY")
            && w[1].is_word("KEY")
            && !def.get(i + 2).is_some_and(|t| t.is_word("DESC"))
    });
    (is_integer, is_pk, is_real)
}

/// `PRIMARY KEY (col)` as a table constraint: the one column's name.
fn primary_key_constraint(def: &[Token]) -> Option<String> {
    let at = def
        .windows(2)
        .position(|w| w[0].is_word("PRIMARY") && w[1].is_word("KEY"))?;
    let inside: Vec<&Token> = def
        .get(at + 2..)?
        .iter()
        .skip_while(|t| **t != Token::Punct('('))
        .skip(1)
        .take_while(|t| **t != Token::Punct(')'))
        .collect();
    match inside.as_slice() {
        [name] => Some(name.text().to_string()),
        [name, dir] if dir.is_word("ASC") || dir.is_word("DESC") => Some(name.text().to_string()),
        _ => None,
    }
}

/// A big-endian `u16` at `at`, or `None` past the end.
fn be16(b: &[u8], at: usize) -> Option<usize> {
    let s = b.get(at..at + 2)?;
    Some(u16::from_be_bytes([s[0], s[1]]) as usize)
}

/// A big-endian `u32` at `at`, or `None` past the end.
fn be32(b: &[u8], at: usize) -> Option<u32> {
    let s = b.get(at..at + 4)?;
    Some(u32::from_be_bytes([s[0], s[1], s[2], s[3]]))
}

/// A varint at `at`: its value and its length, or `None` past the end.
pub fn varint(b: &[u8], at: usize) -> Option<(u64, usize)> {
    let mut v: u64 = 0;
    for i in 0..9 {
        let byte = *b.get(at + i)?;
        if i == 8 {
            return Some(((v << 8) | byte as u64, 9));
        }
        v = (v << 7) | (byte & 0x7f) as u64;
        if byte & 0x80 == 0 {
            return Some((v, i + 1));
        }
    }
    None
}

/// The page size a header's two bytes at offset 16 say, if valid.
fn page_size_of(raw: usize) -> Option<usize> {
    let size = if raw == 1 { 65536 } else { raw };
    (size.is_power_of_two() && (512..=65536).contains(&size)).then_some(size)
}

/// The WAL's committed pages.
struct WalPages<'a> {
    pages: HashMap<u32, &'a [u8]>,
    /// The database size after the last commit, 0 when nothing committed.
    db_pages: u32,
    page_size: usize,
}

/// The WAL checksum (§4.2) of `data` (a multiple of 8 bytes), continuing
/// from `s`.
fn wal_checksum(big_endian: bool, data: &[u8], s: (u32, u32)) -> (u32, u32) {
    let (mut s0, mut s1) = s;
    let (words, _) = data.as_chunks::<8>();
    for w in words {
        let (a, b) = if big_endian {
            (
                u32::from_be_bytes([w[0], w[1], w[2], w[3]]),
                u32::from_be_bytes([w[4], w[5], w[6], w[7]]),
            )
        } else {
            (
                u32::from_le_bytes([w[0], w[1], w[2], w[3]]),
                u32::from_le_bytes([w[4], w[5], w[6], w[7]]),
            )
        };
        s0 = s0.wrapping_add(a).wrapping_add(s1);
        s1 = s1.wrapping_add(b).wrapping_add(s0);
    }
    (s0, s1)
}

/// Reads a WAL: its committed pages (`None` when the WAL is empty or its
/// header is damaged) and what it held.
fn read_wal(wal: &[u8], db_page_size: Option<usize>) -> (Option<WalPages<'_>>, WalSummary) {
    let mut summary = WalSummary::default();
    if wal.is_empty() {
        return (None, summary);
    }
    let header = match wal_header(wal, db_page_size) {
        Ok(h) => h,
        Err(why) => {
            summary.ignored = Some(why);
            return (None, summary);
        }
    };
    let (big_endian, page_size, salts, mut sum) = header;
    let frame_len = 24 + page_size;
    summary.frames = (wal.len() - 32) / frame_len;
    let mut committed = HashMap::new();
    let mut pending: Vec<(u32, &[u8])> = Vec::new();
    let mut db_pages = 0;
    let mut valid = 0;
    for f in 0..summary.frames {
        let at = 32 + f * frame_len;
        let Some(frame) = wal.get(at..at + frame_len) else {
            break;
        };
        let (head, page) = frame.split_at(24);
        let field = |i: usize| be32(head, i * 4).unwrap_or(0);
        if (field(2), field(3)) != salts || field(0) == 0 {
            break;
        }
        sum = wal_checksum(big_endian, &head[..8], sum);
        sum = wal_checksum(big_endian, page, sum);
        if sum != (field(4), field(5)) {
            break;
        }
        valid += 1;
        pending.push((field(0), page));
        if field(1) != 0 {
            db_pages = field(1);
            committed.extend(pending.drain(..));
            summary.committed_frames = valid;
            summary.transactions += 1;
        }
    }
    summary.uncommitted_frames = pending.len();
    summary.invalid_frames = summary.frames - valid;
    let pages = WalPages {
        pages: committed,
        db_pages,
        page_size,
    };
    (Some(pages), summary)
}

/// The WAL header's byte order, page size, salts and checksum, or why the
/// WAL is ignored.
#[allow(clippy::type_complexity)]
fn wal_header(
    wal: &[u8],
    db_page_size: Option<usize>,
) -> Result<(bool, usize, (u32, u32), (u32, u32)), String> {
    let field = |i: usize| be32(wal, i * 4).unwrap_or(0);
    if wal.len() < 32 {
        return Err(format!(
            "the WAL is {} bytes, shorter than its 32-byte header",
            wal.len()
        ));
    }
    let big_endian = match field(0) {
        0x377f_0682 => false,
        0x377f_0683 => true,
        m => {
            return Err(format!(
                "the WAL's magic number is {m:#010x}, not 0x377f0682/3"
            ))
        }
    };
    if field(1) != 3_007_000 {
        return Err(format!(
            "WAL format version {} (3007000 expected)",
            field(1)
        ));
    }
    let page_size = field(2) as usize;
    if !(page_size.is_power_of_two() && (512..=65536).contains(&page_size)) {
        return Err(format!("the WAL's page size {page_size} is not valid"));
    }
    if let Some(db) = db_page_size {
        if db != page_size {
            return Err(format!(
                "the WAL's page size {page_size} differs from the database's {db}"
            ));
        }
    }
    let sum = wal_checksum(big_endian, &wal[..24], (0, 0));
    if sum != (field(6), field(7)) {
        return Err("the WAL header's checksum does not match".to_string());
    }
    Ok((big_endian, page_size, (field(4), field(5)), sum))
}

/// An open database: the file's bytes, the WAL's committed pages over
/// them, and the schema.
pub struct Database<'a> {
    file: &'a [u8],
    wal: Option<WalPages<'a>>,
    wal_summary: Option<WalSummary>,
    header: DbHeader,
    /// Pages that can be read at all (in the file or in the WAL): the size
    /// of a visit map.
    available: u32,
    tables: Vec<Table>,
}

impl<'a> Database<'a> {
    /// Opens a database from the file's bytes and, when given, its `-wal`
    /// file's. A main file of zero bytes is allowed when the WAL holds page 1
    /// (a database never checkpointed).
    pub fn open(file: &'a [u8], wal: Option<&'a [u8]>) -> Result<Database<'a>, SqliteError> {
        let file_page_size = if file.is_empty() && wal.is_some() {
            None
        } else {
            Some(file_header_page_size(file)?)
        };
        let (wal_pages, wal_summary) = match wal {
            Some(w) => {
                let (p, s) = read_wal(w, file_page_size);
                (p, Some(s))
            }
            None => (None, None),
        };
        let page_size = match (file_page_size, &wal_pages) {
            (Some(s), _) => s,
            (None, Some(w)) => w.page_size,
            (None, None) => {
                return Err(SqliteError::file(
                    "the database file is empty and its WAL holds no valid page 1",
                ))
            }
        };
        let page1 = match wal_pages.as_ref().and_then(|w| w.pages.get(&1)) {
            Some(p) => *p,
            None => file.get(..page_size).ok_or_else(|| {
                SqliteError::file(format!(
                    "the file is {} bytes, shorter than its first page ({page_size} bytes)",
                    file.len()
                ))
            })?,
        };
        let mut header = parse_header(page1, page_size)?;
        let file_pages = (file.len() / page_size) as u32;
        if let Some(w) = wal_pages.as_ref().filter(|w| w.db_pages > 0) {
            header.page_count = w.db_pages;
        } else if header.page_count == 0 {
            header.page_count = file_pages;
        }
        let wal_max = wal_pages
            .as_ref()
            .and_then(|w| w.pages.keys().max().copied())
            .unwrap_or(0);
        let available = header.page_count.min(file_pages.max(wal_max));
        let mut db = Database {
            file,
            wal: wal_pages,
            wal_summary,
            header,
            available,
            tables: Vec::new(),
        };
        db.tables = db.read_schema()?;
        Ok(db)
    }

    pub fn header(&self) -> &DbHeader {
        &self.header
    }

    /// What the WAL held, when one was given.
    pub fn wal_summary(&self) -> Option<&WalSummary> {
        self.wal_summary.as_ref()
    }

    /// The tables of the schema (without `sqlite_schema` itself).
    pub fn tables(&self) -> &[Table] {
        &self.tables
    }

    /// A table by name (ASCII case-insensitive).
    pub fn table(&self, name: &str) -> Option<&Table> {
        self.tables
            .iter()
            .find(|t| t.name.eq_ignore_ascii_case(name))
    }

    /// Page `n` whole (page size bytes), from the WAL when it has it.
    pub fn page(&self, n: u32) -> Result<&'a [u8], SqliteError> {
        if n == 0 || n > self.header.page_count {
            return Err(SqliteError::page(
                n,
                format!(
                    "page number {n} is out of range (the database has {} pages)",
                    self.header.page_count
                ),
            ));
        }
        if let Some(p) = self.wal.as_ref().and_then(|w| w.pages.get(&n)) {
            return Ok(p);
        }
        let ps = self.header.page_size;
        let range = (n as usize - 1)
            .checked_mul(ps)
            .and_then(|start| Some(start..start.checked_add(ps)?));
        range.and_then(|r| self.file.get(r)).ok_or_else(|| {
            SqliteError::page(
                n,
                format!(
                    "the page lies past the end of the file ({} bytes, {} whole pages of {ps}): \
                     the file is cut short",
                    self.file.len(),
                    self.file.len() / ps
                ),
            )
        })
    }

    /// Every row of `table`, in rowid order, handed to `visit`; an error
    /// from `visit` stops the read and is returned.
    pub fn for_each_row<F, E>(&self, table: &Table, mut visit: F) -> Result<(), E>
    where
        F: FnMut(Row<'a>) -> Result<(), E>,
        E: From<SqliteError>,
    {
        if table.without_rowid {
            return Err(E::from(SqliteError::file(format!(
                "table {} is a WITHOUT ROWID table, which this reader does not read",
                table.name
            ))));
        }
        let mut visited = vec![false; self.available as usize + 1];
        let mut stack = vec![table.root_page];
        while let Some(n) = stack.pop() {
            let page = self.page(n)?;
            self.mark_visited(&mut visited, n)?;
            let hdr = if n == 1 { 100 } else { 0 };
            let usable = self.header.usable_size();
            let kind = *page.get(hdr).unwrap_or(&0);
            let cells = be16(page, hdr + 3).unwrap_or(0);
            let array = hdr + if kind == 0x05 { 12 } else { 8 };
            if array + 2 * cells > usable {
                let m = format!("{cells} cells do not fit the page's {usable} usable bytes");
                return Err(SqliteError::page(n, m).into());
            }
            let cell_at = |i: usize| be16(page, array + 2 * i).unwrap_or(0);
            match kind {
                0x0d => {
                    for i in 0..cells {
                        let row = self.leaf_cell(page, n, cell_at(i), table, &mut visited)?;
                        visit(row)?;
                    }
                }
                0x05 => {
                    stack.push(be32(page, hdr + 8).unwrap_or(0));
                    for i in (0..cells).rev() {
                        let at = cell_at(i);
                        let child = be32(&page[..usable], at).ok_or_else(|| {
                            SqliteError::page(
                                n,
                                format!("cell {i} at byte {at} runs past the page"),
                            )
                        })?;
                        stack.push(child);
                    }
                }
                0x02 | 0x0a => {
                    let m = format!(
                        "an index b-tree page where table {}'s b-tree was expected",
                        table.name
                    );
                    return Err(SqliteError::page(n, m).into());
                }
                k => {
                    let m = format!(
                        "not a b-tree page (type byte {k:#04x}) in table {}",
                        table.name
                    );
                    return Err(SqliteError::page(n, m).into());
                }
            }
        }
        Ok(())
    }

    /// Every row of `table`, in rowid order.
    pub fn rows(&self, table: &Table) -> Result<Vec<Row<'a>>, SqliteError> {
        let mut rows = Vec::new();
        self.for_each_row(table, |r| -> Result<(), SqliteError> {
            rows.push(r);
            Ok(())
        })?;
        Ok(rows)
    }

    fn mark_visited(&self, visited: &mut [bool], n: u32) -> Result<(), SqliteError> {
        match visited.get_mut(n as usize) {
            Some(seen) if *seen => Err(SqliteError::page(
                n,
                "the page is reached a second time: a cycle in the b-tree or an overflow chain",
            )),
            Some(seen) => {
                *seen = true;
                Ok(())
            }
            // `page(n)` succeeded, so n is within `available`.
            None => Ok(()),
        }
    }

    /// The row in the leaf cell at byte `at` of page `n`.
    fn leaf_cell(
        &self,
        page: &'a [u8],
        n: u32,
        at: usize,
        table: &Table,
        visited: &mut [bool],
    ) -> Result<Row<'a>, SqliteError> {
        let usable = self.header.usable_size();
        let page = &page[..usable];
        let past = || SqliteError::page(n, format!("the cell at byte {at} runs past the page"));
        let (size, a) = varint(page, at).ok_or_else(past)?;
        let (rowid, b) = varint(page, at + a).ok_or_else(past)?;
        let rowid = rowid as i64;
        if size > i32::MAX as u64 {
            return Err(SqliteError::page(
                n,
                format!("row {rowid}: a payload of {size} bytes is beyond SQLite's limit"),
            ));
        }
        let size = size as usize;
        let start = at + a + b;
        let local = local_payload(size, usable);
        let needed = (size - local).div_ceil(usable - 4);
        if needed > self.available as usize {
            return Err(SqliteError::page(
                n,
                format!(
                    "row {rowid}: a payload of {size} bytes needs {needed} overflow pages, \
                     more than the database's {} pages",
                    self.available
                ),
            ));
        }
        let local_bytes = page.get(start..start + local).ok_or_else(past)?;
        let payload = if local == size {
            Cow::Borrowed(local_bytes)
        } else {
            let first = be32(page, start + local).ok_or_else(past)?;
            Cow::Owned(self.overflow(n, rowid, local_bytes, size, first, visited)?)
        };
        let mut values = record_values(payload).map_err(|e| {
            SqliteError::page(n, format!("row {rowid} of table {}: {e}", table.name))
        })?;
        for (v, &real) in values.iter_mut().zip(&table.real_affinity) {
            if let (Value::Integer(i), true) = (&*v, real) {
                *v = Value::Real(*i as f64);
            }
        }
        if let Some(alias) = table.rowid_alias {
            if values.len() <= alias {
                values.resize(alias + 1, Value::Null);
            }
            values[alias] = Value::Integer(rowid);
        }
        Ok(Row {
            rowid,
            page: n,
            values,
        })
    }

    /// A payload of `size` bytes: `local` from the leaf, the rest along the
    /// overflow chain from page `first`.
    fn overflow(
        &self,
        leaf: u32,
        rowid: i64,
        local: &[u8],
        size: usize,
        first: u32,
        visited: &mut [bool],
    ) -> Result<Vec<u8>, SqliteError> {
        let per_page = self.header.usable_size() - 4;
        let mut payload = Vec::with_capacity(size);
        payload.extend_from_slice(local);
        let mut next = first;
        while payload.len() < size {
            if next == 0 {
                return Err(SqliteError::page(
                    leaf,
                    format!(
                        "row {rowid}: the overflow chain ends after {} of {size} bytes",
                        payload.len()
                    ),
                ));
            }
            let page = self.page(next)?;
            self.mark_visited(visited, next)?;
            let take = (size - payload.len()).min(per_page);
            payload.extend_from_slice(&page[4..4 + take]);
            next = be32(page, 0).unwrap_or(0);
        }
        Ok(payload)
    }

    /// Reads `sqlite_schema` (page 1): its tables.
    fn read_schema(&self) -> Result<Vec<Table>, SqliteError> {
        let schema = Table {
            name: "sqlite_schema".to_string(),
            root_page: 1,
            columns: ["type", "name", "tbl_name", "rootpage", "sql"]
                .map(String::from)
                .to_vec(),
            rowid_alias: None,
            real_affinity: vec![false; 5],
            without_rowid: false,
        };
        let mut tables = Vec::new();
        self.for_each_row(&schema, |row| -> Result<(), SqliteError> {
            if row.get(0).as_text() != Some("table") {
                return Ok(());
            }
            let name = row.get(1).as_text().unwrap_or("").to_string();
            let root = row.get(3).as_integer().unwrap_or(0);
            let sql = row.get(4).as_text().unwrap_or("");
            if root <= 0 || sql.is_empty() {
                // A virtual table: no b-tree of its own.
                return Ok(());
            }
            let root = u32::try_from(root).map_err(|_| {
                SqliteError::page(
                    row.page,
                    format!("table {name}: root page {root} is not valid"),
                )
            })?;
            let table = Table::from_sql(&name, root, sql)
                .map_err(|e| SqliteError::page(row.page, format!("the schema: {e}")))?;
            tables.push(table);
            Ok(())
        })?;
        Ok(tables)
    }
}

/// The page size in the file's header, after checking the magic string.
fn file_header_page_size(file: &[u8]) -> Result<usize, SqliteError> {
    if file.len() < 100 {
        return Err(SqliteError::file(format!(
            "not an SQLite database: the file is {} bytes, shorter than the 100-byte header",
            file.len()
        )));
    }
    if &file[..16] != MAGIC {
        return Err(SqliteError::file(
            "not an SQLite database: it does not begin with \"SQLite format 3\\0\"",
        ));
    }
    let raw = be16(file, 16).unwrap_or(0);
    page_size_of(raw).ok_or_else(|| {
        SqliteError::file(format!(
            "the database header's page size {raw} is not a power of two from 512 to 65536"
        ))
    })
}

/// The database header on page 1; `page_count` is 0 when the in-header
/// size is not valid.
fn parse_header(page1: &[u8], page_size: usize) -> Result<DbHeader, SqliteError> {
    let err = |m: String| SqliteError::file(format!("the database header: {m}"));
    if page1.get(..16) != Some(&MAGIC[..]) {
        return Err(err(
            "page 1 does not begin with \"SQLite format 3\\0\"".into()
        ));
    }
    let byte = |i: usize| *page1.get(i).unwrap_or(&0);
    let field = |i: usize| be32(page1, i).unwrap_or(0);
    let raw = be16(page1, 16).unwrap_or(0);
    if page_size_of(raw) != Some(page_size) {
        return Err(err(format!(
            "page size {raw} where {page_size} was expected"
        )));
    }
    let (write_version, read_version) = (byte(18), byte(19));
    if !(1..=2).contains(&read_version) {
        return Err(err(format!(
            "file format read version {read_version}: only 1 (rollback journal) and 2 (WAL) are read"
        )));
    }
    let reserved = byte(20) as usize;
    if page_size - reserved < 480 {
        return Err(err(format!(
            "{reserved} reserved bytes leave fewer than 480 usable bytes in a {page_size}-byte page"
        )));
    }
    if (byte(21), byte(22), byte(23)) != (64, 32, 32) {
        return Err(err(format!(
            "payload fractions {}, {}, {} (64, 32, 32 expected)",
            byte(21),
            byte(22),
            byte(23)
        )));
    }
    let text_encoding = field(56);
    match text_encoding {
        0 | 1 => {}
        2 | 3 => {
            return Err(err(format!(
                "the text encoding is UTF-16{}: only UTF-8 databases are read",
                if text_encoding == 2 { "le" } else { "be" }
            )))
        }
        e => return Err(err(format!("text encoding {e} is not 1, 2 or 3"))),
    }
    let in_header = field(28);
    let page_count = if in_header != 0 && field(24) == field(92) {
        in_header
    } else {
        0
    };
    Ok(DbHeader {
        page_size,
        reserved,
        write_version,
        read_version,
        page_count,
        text_encoding: 1,
    })
}

/// How many of a table leaf cell's `size` payload bytes stay on the page
/// (§1.6): all when they fit X = U − 35, else K or M.
pub fn local_payload(size: usize, usable: usize) -> usize {
    let x = usable - 35;
    if size <= x {
        return size;
    }
    let m = ((usable - 12) * 32 / 255) - 23;
    let k = m + (size - m) % (usable - 4);
    if k <= x {
        k
    } else {
        m
    }
}

/// The values of a record (§2.1), borrowing from the payload when it is
/// borrowed.
fn record_values(payload: Cow<'_, [u8]>) -> Result<Vec<Value<'_>>, String> {
    match payload {
        Cow::Borrowed(b) => record_values_in(b),
        Cow::Owned(v) => Ok(record_values_in(&v)?
            .into_iter()
            .map(Value::into_owned)
            .collect()),
    }
}

/// The values of the record `bytes`.
fn record_values_in(bytes: &[u8]) -> Result<Vec<Value<'_>>, String> {
    let (header_len, a) = varint(bytes, 0).ok_or("the record header is cut short")?;
    let header_len = usize::try_from(header_len).unwrap_or(usize::MAX);
    if header_len > bytes.len() || header_len < a {
        return Err(format!(
            "a record header of {header_len} bytes in a record of {}",
            bytes.len()
        ));
    }
    let mut values = Vec::with_capacity(8);
    let (mut h, mut body) = (a, header_len);
    while h < header_len {
        let col = values.len();
        let (serial, n) = varint(bytes, h).ok_or("the record header is cut short")?;
        h += n;
        let len = match serial {
            0 | 8 | 9 => 0,
            1..=4 => serial as usize,
            5 => 6,
            6 | 7 => 8,
            10 | 11 => return Err(format!("column {col}: reserved serial type {serial}")),
            _ => usize::try_from((serial - 12) / 2).unwrap_or(usize::MAX),
        };
        let raw = body
            .checked_add(len)
            .and_then(|end| bytes.get(body..end))
            .ok_or_else(|| {
                format!(
                    "column {col}: {len} bytes at byte {body} run past the record's {} bytes",
                    bytes.len()
                )
            })?;
        body += len;
        values.push(match serial {
            0 => Value::Null,
            1..=6 => Value::Integer(be_int(raw)),
            7 => Value::Real(f64::from_bits(be_int(raw) as u64)),
            8 => Value::Integer(0),
            9 => Value::Integer(1),
            s if s % 2 == 0 => Value::Blob(Cow::Borrowed(raw)),
            _ => Value::Text(Cow::Borrowed(
                std::str::from_utf8(raw)
                    .map_err(|_| format!("column {col}: the text is not UTF-8"))?,
            )),
        });
    }
    Ok(values)
}

/// A big-endian two's-complement integer of 1 to 8 bytes.
fn be_int(raw: &[u8]) -> i64 {
    let mut v: i64 = if raw.first().is_some_and(|b| b & 0x80 != 0) {
        -1
    } else {
        0
    };
    for &b in raw {
        v = (v << 8) | b as i64;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varints_of_one_to_nine_bytes() {
        assert_eq!(varint(&[0x05], 0), Some((5, 1)));
        assert_eq!(varint(&[0x81, 0x00], 0), Some((128, 2)));
        assert_eq!(varint(&[0xff; 9], 0), Some((u64::MAX, 9)));
        assert_eq!(varint(&[0x81], 0), None);
    }

    #[test]
    fn local_payload_follows_the_spec_thresholds() {
        // U = 4096: X = 4061, M = 489.
        assert_eq!(local_payload(4061, 4096), 4061);
        // P = 5000: K = 489 + (4511 % 4092) = 908 <= X.
        assert_eq!(local_payload(5000, 4096), 908);
        // P = 4062: K = 489 + 3573 = 4062 > X, so M.
        assert_eq!(local_payload(4062, 4096), 489);
    }

    #[test]
    fn integers_are_sign_extended() {
        assert_eq!(be_int(&[0xff]), -1);
        assert_eq!(be_int(&[0x01, 0x00]), 256);
        assert_eq!(be_int(&[0x80, 0, 0, 0, 0, 0]), -(1 << 47));
    }

    #[test]
    fn create_table_columns_and_rowid_alias() {
        let t = Table::from_sql(
            "messages",
            5,
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, \
             -- a comment, with a comma\n \"time stamp\" INTEGER, data BLOB NOT NULL)",
        )
        .unwrap();
        assert_eq!(t.columns, ["id", "topic_id", "time stamp", "data"]);
        assert_eq!(t.rowid_alias, Some(0));
        let t = Table::from_sql("t", 2, "CREATE TABLE t(a INT PRIMARY KEY, b)").unwrap();
        assert_eq!(t.rowid_alias, None);
        let t =
            Table::from_sql("t", 2, "CREATE TABLE t(a TEXT, b INTEGER, PRIMARY KEY(b))").unwrap();
        assert_eq!((t.columns.len(), t.rowid_alias), (2, Some(1)));
        let t = Table::from_sql("t", 2, "CREATE TABLE t(a INTEGER PRIMARY KEY DESC)").unwrap();
        assert_eq!(t.rowid_alias, None);
        let t = Table::from_sql(
            "t",
            2,
            "CREATE TABLE t(a INTEGER PRIMARY KEY) WITHOUT ROWID",
        )
        .unwrap();
        assert!(t.without_rowid);
    }

    #[test]
    fn wal_checksum_pairs_words() {
        // Two little-endian words 1 and 2: s0 = 1, s1 = 2 + 1 = 3.
        let data = [1, 0, 0, 0, 2, 0, 0, 0];
        assert_eq!(wal_checksum(false, &data, (0, 0)), (1, 3));
        // Continued with the same words: s0 = 1 + 1 + 3 = 5, s1 = 3 + 2 + 5 = 10.
        assert_eq!(wal_checksum(false, &data, (1, 3)), (5, 10));
        assert_eq!(wal_checksum(true, &data, (0, 0)).0, 1 << 24);
    }
}
