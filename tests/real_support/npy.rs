//! Reading the Halmstad annotations: NumPy `.npy` files of two columns,
//! either numeric (`<f8`, `<i8`) or object arrays (`|O`).
//!
//! The `.npy` format (NumPy's NEP 1) is a magic string, a version, a header
//! length and a Python-literal header (`descr`, `fortran_order`, `shape`),
//! then the data. Numeric data is the raw little-endian values in C order.
//! An object array's data is instead a *pickle* of the array: a small
//! stack-machine program (Python's `pickle` protocol 2) that rebuilds an
//! `ndarray` and fills it, by a `BUILD` opcode, with a state tuple
//! `(version, shape, dtype, fortran, items)` whose `items` is a list of
//! Python objects: here plain ints, NumPy `int64` scalars (themselves built
//! by `numpy.core.multiarray.scalar(dtype, 8 raw bytes)`) and `None` for a
//! keypoint left unmatched.
//!
//! [`Pickle`] runs just the opcodes these files use (the protocol's
//! documentation in CPython's `Lib/pickletools.py` lists them); anything else
//! is an error naming the opcode, so a file of another shape fails loudly
//! instead of being misread.
#![allow(dead_code)]

use std::path::Path;

/// A value on the pickle machine's stack.
#[derive(Clone, Debug)]
enum Value {
    Int(i64),
    None,
    Bool(bool),
    Bytes(Vec<u8>),
    Tuple(Vec<Value>),
    List(Vec<Value>),
    /// A class or function named by `GLOBAL`: "module name".
    Global(String),
    /// The result of calling something we do not model (e.g. `dtype('O8')`).
    Opaque,
    /// An `ndarray` once `BUILD` has given it its state.
    Array {
        shape: Vec<usize>,
        items: Vec<Value>,
    },
    Mark,
}

/// Rows of a two-column array; a row holding a `None` (object arrays) is
/// `None`. Panics with the file's name when it cannot be read.
pub fn read_pairs(path: &Path) -> Vec<Option<[f64; 2]>> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn parse(b: &[u8]) -> Result<Vec<Option<[f64; 2]>>, String> {
    if b.len() < 10 || &b[..6] != b"\x93NUMPY" {
        return Err("not a .npy file".into());
    }
    let (len, start) = if b[6] == 1 {
        (u16::from_le_bytes([b[8], b[9]]) as usize, 10)
    } else {
        (u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize, 12)
    };
    let header = std::str::from_utf8(b.get(start..start + len).ok_or("truncated header")?)
        .map_err(|_| "header is not text")?;
    if header.contains("'fortran_order': True") {
        return Err("Fortran-order arrays are not read".into());
    }
    let data = &b[start + len..];
    let values: Vec<Option<f64>> = if header.contains("'|O'") {
        let (shape, items) = Pickle::default().run(data)?;
        if shape.len() != 2 || shape[1] != 2 || items.len() != shape[0] * 2 {
            return Err(format!("object array of shape {shape:?}, expected N x 2"));
        }
        items
            .iter()
            .map(|v| match v {
                Value::Int(i) => Ok(Some(*i as f64)),
                Value::None => Ok(None),
                other => Err(format!("object array item {other:?} is not an int or None")),
            })
            .collect::<Result<_, _>>()?
    } else {
        let float = header.contains("'<f8'");
        if !float && !header.contains("'<i8'") {
            return Err(format!("unsupported dtype in header {header}"));
        }
        data.chunks_exact(8)
            .map(|c| {
                let a: [u8; 8] = c.try_into().unwrap();
                Some(if float {
                    f64::from_le_bytes(a)
                } else {
                    i64::from_le_bytes(a) as f64
                })
            })
            .collect()
    };
    if !values.len().is_multiple_of(2) {
        return Err(format!("{} values do not make rows of two", values.len()));
    }
    Ok(values
        .chunks_exact(2)
        .map(|c| Some([c[0]?, c[1]?]))
        .collect())
}

/// The pickle machine: a stack, a memo and a read position.
#[derive(Default)]
struct Pickle {
    stack: Vec<Value>,
    memo: std::collections::HashMap<u32, Value>,
}

impl Pickle {
    fn pop(&mut self) -> Result<Value, String> {
        self.stack
            .pop()
            .ok_or_else(|| "pickle stack underflow".to_string())
    }

    /// Everything above the topmost mark, removing the mark.
    fn pop_to_mark(&mut self) -> Result<Vec<Value>, String> {
        let at = self
            .stack
            .iter()
            .rposition(|v| matches!(v, Value::Mark))
            .ok_or("no mark on the pickle stack")?;
        let items = self.stack.split_off(at + 1);
        self.stack.pop();
        Ok(items)
    }

    fn pop_n(&mut self, n: usize) -> Result<Vec<Value>, String> {
        if self.stack.len() < n {
            return Err("pickle stack underflow".into());
        }
        Ok(self.stack.split_off(self.stack.len() - n))
    }

    /// Runs the program; returns the built array's shape and items.
    fn run(mut self, p: &[u8]) -> Result<(Vec<usize>, Vec<Value>), String> {
        let mut i = 0;
        let take = |i: &mut usize, n: usize| -> Result<&[u8], String> {
            let s = p.get(*i..*i + n).ok_or("truncated pickle")?;
            *i += n;
            Ok(s)
        };
        loop {
            let op = *take(&mut i, 1)?.first().unwrap();
            match op {
                0x80 => {
                    take(&mut i, 1)?; // PROTO n
                }
                b'c' => {
                    // GLOBAL "module\nname\n"
                    let rest = &p[i..];
                    let mut lines = rest.splitn(3, |c| *c == b'\n');
                    let (m, n) = (lines.next().unwrap_or(&[]), lines.next().unwrap_or(&[]));
                    i += m.len() + n.len() + 2;
                    let name = format!(
                        "{} {}",
                        String::from_utf8_lossy(m),
                        String::from_utf8_lossy(n)
                    );
                    self.stack.push(Value::Global(name));
                }
                b'q' => {
                    let k = take(&mut i, 1)?[0] as u32; // BINPUT
                    let top = self.stack.last().ok_or("BINPUT on an empty stack")?.clone();
                    self.memo.insert(k, top);
                }
                b'r' => {
                    let k = u32::from_le_bytes(take(&mut i, 4)?.try_into().unwrap());
                    let top = self
                        .stack
                        .last()
                        .ok_or("LONG_BINPUT on an empty stack")?
                        .clone();
                    self.memo.insert(k, top);
                }
                b'h' | b'j' => {
                    let k = if op == b'h' {
                        take(&mut i, 1)?[0] as u32
                    } else {
                        u32::from_le_bytes(take(&mut i, 4)?.try_into().unwrap())
                    };
                    let v = self.memo.get(&k).ok_or(format!("memo {k} unset"))?.clone();
                    self.stack.push(v);
                }
                b'K' => self.stack.push(Value::Int(take(&mut i, 1)?[0] as i64)),
                b'M' => {
                    let v = u16::from_le_bytes(take(&mut i, 2)?.try_into().unwrap());
                    self.stack.push(Value::Int(v as i64));
                }
                b'J' => {
                    let v = i32::from_le_bytes(take(&mut i, 4)?.try_into().unwrap());
                    self.stack.push(Value::Int(v as i64));
                }
                b'N' => self.stack.push(Value::None),
                0x88 => self.stack.push(Value::Bool(true)),
                0x89 => self.stack.push(Value::Bool(false)),
                b'U' | b'C' => {
                    // SHORT_BINSTRING / SHORT_BINBYTES: one length byte
                    let n = take(&mut i, 1)?[0] as usize;
                    self.stack.push(Value::Bytes(take(&mut i, n)?.to_vec()));
                }
                b'T' | b'B' => {
                    let n = u32::from_le_bytes(take(&mut i, 4)?.try_into().unwrap()) as usize;
                    self.stack.push(Value::Bytes(take(&mut i, n)?.to_vec()));
                }
                b'(' => self.stack.push(Value::Mark),
                b')' => self.stack.push(Value::Tuple(Vec::new())),
                b't' => {
                    let items = self.pop_to_mark()?;
                    self.stack.push(Value::Tuple(items));
                }
                0x85..=0x87 => {
                    let items = self.pop_n((op - 0x84) as usize)?;
                    self.stack.push(Value::Tuple(items));
                }
                b']' => self.stack.push(Value::List(Vec::new())),
                b'a' => {
                    let v = self.pop()?;
                    match self.stack.last_mut() {
                        Some(Value::List(l)) => l.push(v),
                        _ => return Err("APPEND to a non-list".into()),
                    }
                }
                b'e' => {
                    let items = self.pop_to_mark()?;
                    match self.stack.last_mut() {
                        Some(Value::List(l)) => l.extend(items),
                        _ => return Err("APPENDS to a non-list".into()),
                    }
                }
                b'R' => {
                    let args = self.pop()?;
                    let callable = self.pop()?;
                    let v = reduce(&callable, &args);
                    self.stack.push(v);
                }
                b'b' => {
                    let state = self.pop()?;
                    let obj = self.pop()?;
                    self.stack.push(build(obj, state));
                }
                b'.' => {
                    return match self.pop()? {
                        Value::Array { shape, items } => Ok((shape, items)),
                        other => Err(format!("pickle does not hold an array but {other:?}")),
                    };
                }
                _ => {
                    return Err(format!(
                        "pickle opcode 0x{op:02x} at byte {} not read",
                        i - 1
                    ))
                }
            }
        }
    }
}

/// `callable(*args)` for the one call whose value matters here:
/// `numpy.core.multiarray.scalar(dtype, raw)` of an 8-byte integer.
fn reduce(callable: &Value, args: &Value) -> Value {
    if let (Value::Global(name), Value::Tuple(a)) = (callable, args) {
        if name.ends_with(" scalar") {
            if let Some(Value::Bytes(raw)) = a.get(1) {
                if let Ok(b) = <[u8; 8]>::try_from(raw.as_slice()) {
                    return Value::Int(i64::from_le_bytes(b));
                }
            }
        }
    }
    Value::Opaque
}

/// `obj.__setstate__(state)`: an ndarray's state is
/// `(version, shape, dtype, fortran, items)`; other states are ignored.
fn build(obj: Value, state: Value) -> Value {
    if let Value::Tuple(s) = &state {
        if let (Some(Value::Tuple(shape)), Some(Value::List(items))) = (s.get(1), s.last()) {
            let shape: Option<Vec<usize>> = shape
                .iter()
                .map(|v| match v {
                    Value::Int(n) => usize::try_from(*n).ok(),
                    _ => None,
                })
                .collect();
            if let Some(shape) = shape {
                return Value::Array {
                    shape,
                    items: items.clone(),
                };
            }
        }
    }
    obj
}
