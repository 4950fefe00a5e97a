//! The ISO 10303-21 ("Part 21") exchange structure: a tokenizer and a parser of the `DATA`
//! section into an entity table keyed by `#id`.
//!
//! Only the syntax is handled here; what entities mean is for [`crate::model`]. The parser is
//! linear in the file size and recursion is bounded ([`MAX_NESTING`]), so a hostile file can
//! neither hang it nor overflow the stack. Line numbers are counted only when an error is
//! reported (counting them per token made a 4 MB file quadratic: 100k strings times the
//! newlines before each); `Parser::scanned` counts that work so a test can hold it linear.

use std::collections::HashMap;

use crate::error::{Result, StepError};

/// The deepest nesting of parameter lists accepted (real files use 3 or 4: a B-spline
/// surface's control net is a list of lists).
pub(crate) const MAX_NESTING: usize = 32;

/// One parameter value of an entity instance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    /// An integer.
    Int(i64),
    /// A real.
    Real(f64),
    /// A string, with `''` and the Part 21 escapes decoded (`decode_string`).
    Str(String),
    /// An enumeration value without its dots (`.T.` is `Enum("T")`).
    Enum(String),
    /// A reference to another instance (`#23`).
    Ref(u64),
    /// A list `( ... )`.
    List(Vec<Value>),
    /// A typed parameter `LENGTH_MEASURE(1.E-07)`.
    Typed(String, Box<Value>),
    /// `$`: the value is absent.
    Null,
    /// `*`: derived.
    Derived,
    /// A binary `"..."` (kept as text).
    Binary(String),
}

/// One entity instance: `#id=NAME(...)` has one record, a complex instance
/// `#id=(A(...) B(...))` has one record per partial type, in file order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Instance {
    /// The `#id`.
    pub(crate) id: u64,
    /// `(NAME, parameters)` per record; names upper case.
    pub(crate) records: Vec<(String, Vec<Value>)>,
}

impl Instance {
    /// The record named `name`, if the instance has one.
    pub(crate) fn record(&self, name: &str) -> Option<&[Value]> {
        self.records
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, p)| p.as_slice())
    }

    /// The entity name for messages: the simple name, or the partial names joined by `+`.
    pub(crate) fn name(&self) -> String {
        self.records
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join("+")
    }

    /// `true` if the instance is (or, complex, contains) an entity called `name`.
    pub(crate) fn is(&self, name: &str) -> bool {
        self.records.iter().any(|(n, _)| n == name)
    }
}

/// The most entity instances one file may hold. The index costs 20 bytes per instance, so a
/// file at kerf's 1 GiB input limit made of the shortest instances (`#1=A();`, 7 bytes) would
/// need 3 GB for it alone; real files hold a few million (a 100 MB assembly: ~2 M).
pub(crate) const MAX_INSTANCES: usize = 20_000_000;

/// One instance in the index: where its text starts and which record names it has.
#[derive(Debug, Clone, Copy)]
struct Slot {
    /// The `#id`.
    id: u64,
    /// Byte offset of its `#` in the text.
    start: u32,
    /// Index into [`Exchange::kinds`].
    kind: u32,
}

/// A parsed exchange structure: the whole file's syntax checked once, and an index of its
/// instances (id, offset, record names) instead of their values. An instance's values are
/// parsed again from the text each time it is asked for ([`Exchange::get`]), so the memory
/// is the text plus ~20 bytes per instance, whatever the instances hold, and the work of
/// reading an entity the contours never reach is one syntax pass.
#[derive(Debug, Clone, Default)]
pub(crate) struct Exchange<'t> {
    /// The schema names of `FILE_SCHEMA`.
    pub(crate) schemas: Vec<String>,
    text: &'t [u8],
    /// Every instance of the `DATA` sections, in file order.
    slots: Vec<Slot>,
    /// Indices into `slots`, sorted by id.
    by_id: Vec<u32>,
    /// The distinct lists of record names (`[CIRCLE]`, `[LENGTH_UNIT, NAMED_UNIT, SI_UNIT]`).
    kinds: Vec<Box<[String]>>,
}

impl<'t> Exchange<'t> {
    /// The number of instances.
    pub(crate) fn len(&self) -> usize {
        self.slots.len()
    }

    fn slot_of(&self, id: u64) -> Option<Slot> {
        self.by_id
            .binary_search_by_key(&id, |&k| self.slots[k as usize].id)
            .ok()
            .map(|k| self.slots[self.by_id[k] as usize])
    }

    /// The instance `#id` (parsed from the text now), `None` if the file does not define it.
    ///
    /// # Errors
    /// Only if the text no longer parses, which the first pass rules out.
    pub(crate) fn get(&self, id: u64) -> Result<Option<Instance>> {
        self.slot_of(id).map(|s| self.parse_slot(s)).transpose()
    }

    fn parse_slot(&self, s: Slot) -> Result<Instance> {
        let mut p = Parser {
            s: self.text,
            i: s.start as usize,
            scanned: std::cell::Cell::new(0),
        };
        p.instance()
    }

    /// The ids of every instance that is (or, complex, contains) entity `name`, in file order;
    /// decided from the index, without parsing any instance.
    pub(crate) fn ids_of(&self, name: &str) -> Vec<u64> {
        self.ids_where(|n| n == name)
    }

    /// The ids of the instances of any of `names` (a complex instance is one of them if any
    /// of its records is), each once, ascending.
    pub(crate) fn ids_of_any(&self, names: &[&str]) -> Vec<u64> {
        let mut ids = self.ids_where(|n| names.contains(&n));
        ids.sort_unstable();
        ids.dedup();
        ids
    }

    /// The ids of the instances with a record whose name `is` picks, in file order.
    fn ids_where(&self, is: impl Fn(&str) -> bool) -> Vec<u64> {
        let hit: Vec<bool> = self.kinds.iter().map(|k| k.iter().any(|n| is(n))).collect();
        self.slots
            .iter()
            .filter(|s| hit[s.kind as usize])
            .map(|s| s.id)
            .collect()
    }
}

/// Parses a whole Part 21 file.
///
/// # Errors
/// [`StepError::Syntax`] naming the line and what was expected; [`StepError::DuplicateId`];
/// [`StepError::Budget`] past [`MAX_INSTANCES`] or a text of 4 GiB or more.
pub(crate) fn parse(text: &str) -> Result<Exchange<'_>> {
    parse_counted(text).0
}

/// [`parse`], also returning the work done: the bytes the parser stepped over plus those it
/// scanned again to number lines. A linear parser keeps this within a small multiple of the
/// file size whatever the file holds.
fn parse_counted(text: &str) -> (Result<Exchange<'_>>, usize) {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
        scanned: std::cell::Cell::new(0),
    };
    let r = parse_with(&mut p);
    (r, p.i + p.scanned.get())
}

fn parse_with<'t>(p: &mut Parser<'t>) -> Result<Exchange<'t>> {
    if u32::try_from(p.s.len()).is_err() {
        return Err(StepError::Budget {
            what: "file size".into(),
            limit: u32::MAX as u64,
            place: format!("{} bytes", p.s.len()),
        });
    }
    let mut ex = Exchange {
        text: p.s,
        ..Exchange::default()
    };
    let mut kind_index: HashMap<String, u32> = HashMap::new();
    p.skip_ws()?;
    p.expect_keyword("ISO-10303-21")?;
    p.expect_byte(b';')?;
    let mut in_data = false;
    let mut seen_data = false;
    loop {
        p.skip_ws()?;
        if p.at_end() {
            return Err(p.error("the file ends before END-ISO-10303-21;"));
        }
        if p.peek() == Some(b'#') && in_data {
            if ex.slots.len() >= MAX_INSTANCES {
                return Err(StepError::Budget {
                    what: "entity instances".into(),
                    limit: MAX_INSTANCES as u64,
                    place: format!("line {}", p.line()),
                });
            }
            let start = p.i as u32;
            // The values are checked and dropped: the index keeps where they are.
            let inst = p.instance()?;
            let key = inst.name();
            let next = ex.kinds.len() as u32;
            let kind = *kind_index.entry(key).or_insert_with(|| {
                ex.kinds
                    .push(inst.records.iter().map(|(n, _)| n.clone()).collect());
                next
            });
            ex.slots.push(Slot {
                id: inst.id,
                start,
                kind,
            });
            continue;
        }
        let word = p.keyword()?;
        match word.as_str() {
            "END-ISO-10303-21" => {
                p.skip_ws()?;
                p.expect_byte(b';')?;
                break;
            }
            "HEADER" => p.expect_byte(b';')?,
            "DATA" => {
                p.skip_ws()?;
                if p.peek() == Some(b'(') {
                    // DATA('name', (schemas)); of Part 21 edition 3.
                    p.i += 1;
                    p.params(0)?;
                }
                p.skip_ws()?;
                p.expect_byte(b';')?;
                in_data = true;
                seen_data = true;
            }
            "ENDSEC" => {
                p.skip_ws()?;
                p.expect_byte(b';')?;
                in_data = false;
            }
            _ if !in_data => {
                // A header entity: FILE_DESCRIPTION(...); FILE_NAME(...); FILE_SCHEMA(...);
                p.skip_ws()?;
                p.expect_byte(b'(')?;
                let params = p.params(0)?;
                p.skip_ws()?;
                p.expect_byte(b';')?;
                if word == "FILE_SCHEMA" {
                    if let Some(Value::List(l)) = params.first() {
                        ex.schemas = l
                            .iter()
                            .filter_map(|v| match v {
                                Value::Str(s) => Some(clip(s)),
                                _ => None,
                            })
                            .take(16)
                            .collect();
                    }
                }
            }
            _ => {
                return Err(p.error(&format!(
                    "expected #id=... or ENDSEC, found {}",
                    clip(&word)
                )))
            }
        }
    }
    if !seen_data {
        return Err(StepError::Syntax {
            line: p.line(),
            message: "no DATA section".into(),
        });
    }
    ex.by_id = (0..ex.slots.len() as u32).collect();
    let slots = &ex.slots;
    ex.by_id
        .sort_unstable_by_key(|&k| (slots[k as usize].id, slots[k as usize].start));
    if let Some(w) = ex
        .by_id
        .windows(2)
        .find(|w| slots[w[0] as usize].id == slots[w[1] as usize].id)
    {
        let second = slots[w[1] as usize];
        return Err(StepError::DuplicateId {
            id: second.id,
            line: p.line_at(second.start as usize),
        });
    }
    Ok(ex)
}

/// At most this many characters of file text are quoted in a message.
pub(crate) const QUOTE_CHARS: usize = 64;

/// `s` as quoted in a message: whole if short, else its first [`QUOTE_CHARS`] characters and
/// the length (an error must not echo megabytes of input).
pub(crate) fn clip(s: &str) -> String {
    match s.char_indices().nth(QUOTE_CHARS) {
        None => s.to_owned(),
        Some((k, _)) => format!("{}... ({} bytes)", &s[..k], s.len()),
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    /// Bytes scanned again to number lines (only when an error is reported).
    scanned: std::cell::Cell<usize>,
}

impl Parser<'_> {
    fn at_end(&self) -> bool {
        self.i >= self.s.len()
    }

    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }

    /// The 1-based line of the current position. It scans the file from its start, so call it
    /// only to report an error, never per token.
    fn line(&self) -> usize {
        self.line_at(self.i)
    }

    /// The 1-based line of byte `pos`; as costly as [`Parser::line`].
    fn line_at(&self, pos: usize) -> usize {
        let head = &self.s[..pos.min(self.s.len())];
        self.scanned.set(self.scanned.get() + head.len());
        1 + head.iter().filter(|&&b| b == b'\n').count()
    }

    fn error(&self, message: &str) -> StepError {
        StepError::Syntax {
            line: self.line(),
            message: message.to_owned(),
        }
    }

    /// Skips white space and `/* ... */` comments.
    fn skip_ws(&mut self) -> Result<()> {
        loop {
            while self.peek().is_some_and(|b| b.is_ascii_whitespace()) {
                self.i += 1;
            }
            if self.s[self.i.min(self.s.len())..].starts_with(b"/*") {
                let start = self.i;
                match self.s[self.i + 2..].windows(2).position(|w| w == b"*/") {
                    Some(k) => self.i += 2 + k + 2,
                    None => {
                        self.i = start;
                        return Err(self.error("unterminated comment /* ..."));
                    }
                }
            } else {
                return Ok(());
            }
        }
    }

    fn expect_byte(&mut self, b: u8) -> Result<()> {
        self.skip_ws()?;
        if self.peek() == Some(b) {
            self.i += 1;
            Ok(())
        } else {
            let found = self.found();
            Err(self.error(&format!("expected '{}', found {found}", b as char)))
        }
    }

    fn found(&self) -> String {
        match self.peek() {
            None => "the end of the file".into(),
            Some(b) if b.is_ascii_graphic() => format!("'{}'", b as char),
            Some(b) => format!("byte 0x{b:02x}"),
        }
    }

    /// A keyword: letters, digits, `_` and `-`, upper-cased.
    fn keyword(&mut self) -> Result<String> {
        self.skip_ws()?;
        let start = self.i;
        while self
            .peek()
            .is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
        {
            self.i += 1;
        }
        if start == self.i {
            let found = self.found();
            return Err(self.error(&format!("expected a keyword, found {found}")));
        }
        Ok(String::from_utf8_lossy(&self.s[start..self.i]).to_ascii_uppercase())
    }

    fn expect_keyword(&mut self, word: &str) -> Result<()> {
        let k = self.keyword()?;
        if k == word {
            Ok(())
        } else {
            Err(self.error(&format!("expected {word}, found {}", clip(&k))))
        }
    }

    /// `#id = NAME(...);` or `#id = (A(...) B(...));`.
    fn instance(&mut self) -> Result<Instance> {
        self.i += 1; // '#'
        let id = self.unsigned()?;
        self.expect_byte(b'=')?;
        self.skip_ws()?;
        let mut records = Vec::new();
        if self.peek() == Some(b'(') {
            self.i += 1;
            loop {
                self.skip_ws()?;
                if self.peek() == Some(b')') {
                    self.i += 1;
                    break;
                }
                let name = self.keyword()?;
                self.expect_byte(b'(')?;
                records.push((name, self.params(1)?));
            }
            if records.is_empty() {
                return Err(self.error(&format!("#{id}: a complex instance with no record")));
            }
        } else {
            let name = self.keyword()?;
            self.expect_byte(b'(')?;
            records.push((name, self.params(0)?));
        }
        self.expect_byte(b';')?;
        Ok(Instance { id, records })
    }

    fn unsigned(&mut self) -> Result<u64> {
        let start = self.i;
        while self.peek().is_some_and(|b| b.is_ascii_digit()) {
            self.i += 1;
        }
        std::str::from_utf8(&self.s[start..self.i])
            .ok()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| self.error("expected an instance number after '#'"))
    }

    /// The parameters after an opening `(` up to and including the matching `)`.
    fn params(&mut self, depth: usize) -> Result<Vec<Value>> {
        if depth > MAX_NESTING {
            return Err(self.error(&format!("lists nested deeper than {MAX_NESTING}")));
        }
        let mut out = Vec::new();
        self.skip_ws()?;
        if self.peek() == Some(b')') {
            self.i += 1;
            return Ok(out);
        }
        loop {
            out.push(self.value(depth)?);
            self.skip_ws()?;
            match self.peek() {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    return Ok(out);
                }
                _ => {
                    let found = self.found();
                    return Err(self.error(&format!("expected ',' or ')', found {found}")));
                }
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Value> {
        self.skip_ws()?;
        let Some(b) = self.peek() else {
            return Err(self.error("the file ends inside a parameter list"));
        };
        match b {
            b'#' => {
                self.i += 1;
                Ok(Value::Ref(self.unsigned()?))
            }
            b'$' => {
                self.i += 1;
                Ok(Value::Null)
            }
            b'*' => {
                self.i += 1;
                Ok(Value::Derived)
            }
            b'(' => {
                self.i += 1;
                Ok(Value::List(self.params(depth + 1)?))
            }
            b'\'' => self.string(),
            b'"' => {
                self.i += 1;
                let start = self.i;
                while self.peek().is_some_and(|b| b != b'"') {
                    self.i += 1;
                }
                if self.at_end() {
                    return Err(self.error("unterminated binary \"..."));
                }
                let text = String::from_utf8_lossy(&self.s[start..self.i]).into_owned();
                self.i += 1;
                Ok(Value::Binary(text))
            }
            b'.' if self
                .s
                .get(self.i + 1)
                .is_some_and(|c| c.is_ascii_alphabetic()) =>
            {
                self.i += 1;
                let start = self.i;
                while self
                    .peek()
                    .is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_')
                {
                    self.i += 1;
                }
                let name = String::from_utf8_lossy(&self.s[start..self.i]).to_ascii_uppercase();
                if self.peek() != Some(b'.') {
                    return Err(self.error("unterminated enumeration .NAME."));
                }
                self.i += 1;
                Ok(Value::Enum(name))
            }
            b'+' | b'-' | b'.' | b'0'..=b'9' => self.number(),
            b if b.is_ascii_alphabetic() || b == b'_' => {
                let name = self.keyword()?;
                self.expect_byte(b'(')?;
                let mut inner = self.params(depth + 1)?;
                let v = if inner.len() == 1 {
                    inner.pop().unwrap_or(Value::Null)
                } else {
                    Value::List(inner)
                };
                Ok(Value::Typed(name, Box::new(v)))
            }
            _ => {
                let found = self.found();
                Err(self.error(&format!("expected a parameter, found {found}")))
            }
        }
    }

    fn number(&mut self) -> Result<Value> {
        let start = self.i;
        if matches!(self.peek(), Some(b'+' | b'-')) {
            self.i += 1;
        }
        let mut real = false;
        while let Some(b) = self.peek() {
            match b {
                b'0'..=b'9' => self.i += 1,
                b'.' => {
                    real = true;
                    self.i += 1;
                }
                b'E' | b'e' => {
                    real = true;
                    self.i += 1;
                    if matches!(self.peek(), Some(b'+' | b'-')) {
                        self.i += 1;
                    }
                }
                _ => break,
            }
        }
        let text = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        let bad = || self.error(&format!("not a number: {:?}", clip(text)));
        if real {
            // Part 21 allows "1." and "1.E5"; Rust parses both.
            let v: f64 = text.parse().map_err(|_| bad())?;
            if !v.is_finite() {
                return Err(bad());
            }
            Ok(Value::Real(v))
        } else {
            text.parse().map(Value::Int).map_err(|_| bad())
        }
    }

    /// `'...'` with `''` for a quote and the `\X2\hhhh\X0\`, `\X\hh` and `\S\c` escapes.
    fn string(&mut self) -> Result<Value> {
        let start = self.i;
        self.i += 1;
        let mut raw = Vec::new();
        loop {
            match self.peek() {
                None => {
                    return Err(StepError::Syntax {
                        line: self.line_at(start),
                        message: "unterminated string '...".into(),
                    })
                }
                Some(b'\'') if self.s.get(self.i + 1) == Some(&b'\'') => {
                    raw.push(b'\'');
                    self.i += 2;
                }
                Some(b'\'') => {
                    self.i += 1;
                    break;
                }
                Some(b) => {
                    raw.push(b);
                    self.i += 1;
                }
            }
        }
        Ok(Value::Str(decode_string(&String::from_utf8_lossy(&raw))))
    }
}

/// Decodes the Part 21 string escapes (ISO 10303-21, 6.4.3); anything malformed is kept as
/// written.
///
/// - `\\` is a backslash (`''`, a quote, is undone by the tokenizer);
/// - `\X\hh` is the ISO 8859-1 character `hh`;
/// - `\X2\hhhh...\X0\` is UTF-16 (UCS-2 in the standard), `\X4\hhhhhhhh...\X0\` UCS-4;
/// - `\S\c` is the character `c` + 128 of the current code page, which `\PA\` to `\PI\`
///   select (ISO 8859-1 to -9; `\PA\` at the start of every string). Page A is decoded
///   exactly (the Latin-1 upper half is U+0080-U+00FF); an upper-half character of another
///   page becomes U+FFFD: kerf reads strings for names in its reports only, and says so
///   rather than guess a letter.
fn decode_string(s: &str) -> String {
    if !s.contains('\\') {
        return s.to_owned();
    }
    let hex_units = |hex: &str, width: usize| -> Option<Vec<u32>> {
        if hex.len() % width != 0 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        (0..hex.len() / width)
            .map(|j| u32::from_str_radix(hex.get(width * j..width * (j + 1))?, 16).ok())
            .collect()
    };
    let mut out = String::new();
    let mut rest = s;
    let mut latin1 = true;
    while let Some(k) = rest.find('\\') {
        out.push_str(&rest[..k]);
        rest = &rest[k..];
        if let Some(body) = rest.strip_prefix("\\X2\\") {
            if let Some(end) = body.find("\\X0\\") {
                if let Some(units) = hex_units(&body[..end], 4) {
                    let units: Vec<u16> = units.into_iter().map(|u| u as u16).collect();
                    out.push_str(&String::from_utf16_lossy(&units));
                    rest = &body[end + 4..];
                    continue;
                }
            }
        } else if let Some(body) = rest.strip_prefix("\\X4\\") {
            if let Some(end) = body.find("\\X0\\") {
                if let Some(units) = hex_units(&body[..end], 8) {
                    out.extend(
                        units
                            .into_iter()
                            .map(|u| char::from_u32(u).unwrap_or(char::REPLACEMENT_CHARACTER)),
                    );
                    rest = &body[end + 4..];
                    continue;
                }
            }
        } else if let Some(body) = rest.strip_prefix("\\X\\") {
            if let Some(c) = body.get(..2).and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(char::from(c));
                rest = &body[2..];
                continue;
            }
        } else if let Some(body) = rest.strip_prefix("\\S\\") {
            if let Some(c) = body.chars().next().filter(|c| (' '..='~').contains(c)) {
                out.push(if latin1 {
                    char::from(c as u8 + 0x80)
                } else {
                    char::REPLACEMENT_CHARACTER
                });
                rest = &body[1..];
                continue;
            }
        } else if let Some(body) = rest.strip_prefix("\\P") {
            let page = body.as_bytes();
            if page.len() >= 2 && (b'A'..=b'I').contains(&page[0]) && page[1] == b'\\' {
                latin1 = page[0] == b'A';
                rest = &body[2..];
                continue;
            }
        } else if rest.starts_with("\\\\") {
            out.push('\\');
            rest = &rest[2..];
            continue;
        }
        out.push('\\');
        rest = &rest[1..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_simple_complex_and_typed_instances() {
        let text = "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n\
            #1=CARTESIAN_POINT('it''s',(0.,1.5E1,-2));\n/* comment */\n\
            #2=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n\
            #3=UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#2,'x','');\n\
            ENDSEC;\nEND-ISO-10303-21;\n";
        let ex = parse(text).expect("valid file");
        assert_eq!(ex.schemas, vec!["AUTOMOTIVE_DESIGN".to_string()], "schema");
        let p = ex.get(1).expect("parses").expect("defined");
        assert_eq!(
            p.records[0].1,
            vec![
                Value::Str("it's".into()),
                Value::List(vec![Value::Real(0.0), Value::Real(15.0), Value::Int(-2)])
            ],
            "point parameters"
        );
        assert_eq!(
            ex.get(2).expect("parses").expect("defined").name(),
            "LENGTH_UNIT+NAMED_UNIT+SI_UNIT",
            "complex"
        );
        assert_eq!(
            ex.get(3).expect("parses").expect("defined").records[0].1[0],
            Value::Typed("LENGTH_MEASURE".into(), Box::new(Value::Real(1e-7))),
            "typed"
        );
    }

    #[test]
    fn syntax_errors_name_the_line() {
        let text = "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=LINE('',#2,#3;\nENDSEC;\n";
        let e = parse(text).unwrap_err().to_string();
        assert!(e.contains("line 5"), "{e}");
        let e = parse("ISO-10303-21;\nDATA;\n#1=A('x);\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unterminated string"), "{e}");
        let e = parse("ISO-10303-21;\nDATA;\n#1=A(1);\n#1=A(2);\nENDSEC;\nEND-ISO-10303-21;")
            .unwrap_err()
            .to_string();
        assert!(e.contains("#1 is defined twice"), "{e}");
    }

    /// The review's `flat_points.step` (100k points, 4 MB) timed out: every string literal
    /// numbered its line by scanning the file from the start. The work must grow with the
    /// size, not its square; the old parser scanned ~n^2/2 bytes here.
    #[test]
    fn work_is_linear_in_the_file_size() {
        let file = |n: usize| {
            let mut t = String::from("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n");
            for k in 1..=n {
                t.push_str(&format!("#{k}=CARTESIAN_POINT('p',(0.,1.,2.));\n"));
            }
            t + "ENDSEC;\nEND-ISO-10303-21;\n"
        };
        for n in [1_000, 20_000] {
            let text = file(n);
            let (r, work) = parse_counted(&text);
            assert_eq!(r.expect("valid file").len(), n, "all points indexed");
            assert!(
                work <= 2 * text.len(),
                "{n} points: {work} bytes of work for a {}-byte file",
                text.len()
            );
        }
        // An error still names its line, at the cost of one scan.
        let mut bad = file(20_000);
        bad.truncate(bad.len() - "ENDSEC;\nEND-ISO-10303-21;\n".len());
        bad.push_str("#20001=A('open");
        let (r, work) = parse_counted(&bad);
        let e = r.unwrap_err().to_string();
        assert!(
            e.contains("line 20005") && e.contains("unterminated"),
            "{e}"
        );
        assert!(
            work <= 2 * bad.len(),
            "{work} bytes of work on the error path"
        );
    }

    #[test]
    fn deep_nesting_is_refused_not_overflowed() {
        let text = format!(
            "ISO-10303-21;\nDATA;\n#1=A({}{});\nENDSEC;\nEND-ISO-10303-21;",
            "(".repeat(100_000),
            ")".repeat(100_000)
        );
        let e = parse(&text).unwrap_err().to_string();
        assert!(e.contains("nested deeper"), "{e}");
    }

    #[test]
    fn string_escapes() {
        assert_eq!(decode_string("a\\X2\\00E9\\X0\\b"), "a\u{e9}b", "X2");
        assert_eq!(decode_string("\\X\\E9"), "\u{e9}", "X");
        assert_eq!(
            decode_string("back\\\\slash"),
            "back\\slash",
            "double backslash"
        );
        // \S\ adds 128 in the current page: 'M\S\|ller' is Müller in ISO 8859-1 (| is 0x7C,
        // 0xFC is u-umlaut); the page is A until \P?\ changes it.
        assert_eq!(decode_string("M\\S\\|ller"), "M\u{fc}ller", "S, page A");
        assert_eq!(decode_string("\\PA\\M\\S\\|ller"), "M\u{fc}ller", "PA");
        assert_eq!(
            decode_string("\\PB\\\\S\\9"),
            "\u{fffd}",
            "another page: not guessed"
        );
        assert_eq!(decode_string("\\X4\\0001F600\\X0\\!"), "\u{1f600}!", "X4");
        assert_eq!(
            decode_string("\\X2\\00E900\\X0\\"),
            "\\X2\\00E900\\X0\\",
            "an odd X2 run is kept as written"
        );
        assert_eq!(decode_string("a\\S\\"), "a\\S\\", "S at the end, kept");
        assert_eq!(
            decode_string("\\X2\\+0E9\\X0\\"),
            "\\X2\\+0E9\\X0\\",
            "a sign is not a hex digit"
        );
    }
}
