//! The IGES ASCII fixed-line layout (IGES 5.3 chapter 2): 80-column records with the section
//! letter in column 73 (`S` start, `G` global, `D` directory entry, `P` parameter data, `T`
//! terminate); free-format global and parameter fields separated by the file's own
//! parameter and record delimiters; strings as Holleriths (`5Hhello`).
//!
//! Work is proportional to the file: every byte is looked at a bounded number of times, and a
//! Hollerith's count is checked against the text that is left before anything is taken.

use crate::error::{IgesError, Result};

/// The most directory entries a file may have (a 1.2 MB production part has ~10,000).
pub(crate) const MAX_ENTRIES: usize = 2_000_000;

/// One free-format field.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Token {
    /// Nothing between two delimiters: the field's default.
    Empty,
    /// A Hollerith string.
    Text(String),
    /// A number (or anything else that is not a string), trimmed.
    Raw(String),
}

/// One directory entry with its parameters.
#[derive(Debug, Clone)]
pub(crate) struct Entry {
    /// The sequence number of its first `D` line (odd: 1, 3, 5, ...).
    pub(crate) de: usize,
    /// The entity type number (110, 126, ...).
    pub(crate) ty: i64,
    /// The form number.
    pub(crate) form: i64,
    /// The directory entry of its transformation matrix (0: none).
    pub(crate) transform: i64,
    /// The status number's four pairs: blank, subordinate switch, entity use, hierarchy.
    pub(crate) status: [u8; 4],
    /// The entity label (8 characters at most, trimmed).
    pub(crate) label: String,
    /// The entity subscript number.
    pub(crate) subscript: i64,
    /// The parameters after the entity type.
    pub(crate) params: Vec<Token>,
}

/// The file: its global fields and its entities, in directory order.
#[derive(Debug, Clone)]
pub(crate) struct Iges {
    /// The global section's fields from the third on (index 0 is field 3, the sending
    /// system's product id).
    pub(crate) global: Vec<Token>,
    /// The entities; entry `k` has directory entry number `2k + 1`.
    pub(crate) entries: Vec<Entry>,
}

impl Iges {
    /// The entry whose directory entry number is `de`.
    pub(crate) fn entry(&self, de: usize) -> Option<&Entry> {
        if de % 2 == 0 {
            return None;
        }
        self.entries.get((de - 1) / 2)
    }

    /// Global field `n` (1-based as the standard numbers them; `n >= 3`).
    pub(crate) fn global_field(&self, n: usize) -> &Token {
        self.global.get(n.wrapping_sub(3)).unwrap_or(&Token::Empty)
    }
}

fn syntax(line: usize, message: impl Into<String>) -> IgesError {
    IgesError::Syntax {
        line,
        message: message.into(),
    }
}

/// The file's 80-column records with their numbers: its lines (a `\r` before the line break
/// dropped), numbered from 1. A file without line breaks between its records (IGES defines
/// records of 80 characters, not lines; Open CASCADE reads such files too) is one line whose
/// length is a multiple of 80 with a section letter in column 73 of every 80: it is cut into
/// its records, numbered as if each were a line. A line of 160 characters or more that starts
/// like a record but is not a whole number of them is refused.
fn records(bytes: &[u8]) -> Result<Vec<(usize, &[u8])>> {
    let is_letter = |b: u8| matches!(b, b'S' | b'G' | b'D' | b'P' | b'T');
    let mut out = Vec::new();
    for raw in bytes.split(|&b| b == b'\n') {
        let line = raw.strip_suffix(b"\r").unwrap_or(raw);
        let base = out.len();
        if line.len() >= 160 && is_letter(line[72]) {
            // Records run together: whole 80-column records, each with its section letter.
            if line.len() % 80 != 0 || !line.chunks(80).all(|r| is_letter(r[72])) {
                return Err(syntax(
                    base + 1,
                    format!(
                        "records run together without line breaks, but {} characters are not a whole number of 80-column records each with its section letter in column 73",
                        line.len()
                    ),
                ));
            }
            out.extend(line.chunks(80).enumerate().map(|(i, r)| (base + i + 1, r)));
        } else {
            out.push((base + 1, line));
        }
    }
    Ok(out)
}

/// Reads the layout of a whole file.
pub(crate) fn parse(bytes: &[u8]) -> Result<Iges> {
    let bytes = kerf_io::strip_bom(bytes);
    // (line number, bytes) per section, in order.
    let mut sections: [Vec<(usize, &[u8])>; 5] = Default::default();
    let mut last = 0usize;
    let mut seen_any = false;
    let records = records(bytes)?;
    for &(line_no, line) in &records {
        if line.iter().all(|b| b.is_ascii_whitespace()) {
            continue;
        }
        if line.len() < 73 {
            return Err(syntax(
                line_no,
                format!(
                    "an IGES record has its section letter in column 73; this line has {} columns",
                    line.len()
                ),
            ));
        }
        let letter = line[72];
        let k = match letter {
            b'S' => 0,
            b'G' => 1,
            b'D' => 2,
            b'P' => 3,
            b'T' => 4,
            b'C' if !seen_any => {
                return Err(syntax(
                    line_no,
                    "compressed ASCII IGES is not read: export the file in the fixed 80-column form",
                ))
            }
            b'B' if !seen_any => {
                return Err(syntax(
                    line_no,
                    "binary IGES is not read: export the file in the fixed 80-column form",
                ))
            }
            other => {
                return Err(syntax(
                    line_no,
                    format!(
                        "column 73 holds {:?}, not a section letter (S, G, D, P, T): not an IGES file, or a line was cut",
                        other as char
                    ),
                ))
            }
        };
        if k < last {
            return Err(syntax(
                line_no,
                format!(
                    "a {} line after the {} section: the sections must come in the order S, G, D, P, T",
                    letter as char,
                    ["start", "global", "directory", "parameter", "terminate"][last]
                ),
            ));
        }
        last = k;
        seen_any = true;
        sections[k].push((line_no, line));
    }
    if sections[1].is_empty() {
        return Err(syntax(
            records.len(),
            "no global (G) section: not an IGES file",
        ));
    }
    let global = global(&sections[1])?;
    let (pdelim, rdelim) = (global.0, global.1);
    let d = &sections[2];
    if d.len() % 2 != 0 {
        return Err(syntax(
            d[d.len() - 1].0,
            "the directory section has an odd number of lines (each entry has two)",
        ));
    }
    if d.len() / 2 > MAX_ENTRIES {
        return Err(IgesError::Budget {
            what: "directory entries".into(),
            limit: MAX_ENTRIES as u64,
            place: format!("line {}", d[2 * MAX_ENTRIES].0),
        });
    }
    let p = &sections[3];
    let mut entries = Vec::with_capacity(d.len() / 2);
    for k in 0..d.len() / 2 {
        let (l1, a) = d[2 * k];
        let (l2, b) = d[2 * k + 1];
        let de = 2 * k + 1;
        let ty = field(a, 0, l1)?;
        let pointer = field(a, 1, l1)?;
        let transform = field(a, 6, l1)?;
        let status = status(a, l1)?;
        let ty2 = field(b, 0, l2)?;
        if ty2 != ty {
            return Err(syntax(
                l2,
                format!(
                    "directory entry {de}: its second line names entity type {ty2}, its first {ty}"
                ),
            ));
        }

        let form = field(b, 4, l2)?;
        let label = String::from_utf8_lossy(&b[56..64]).trim().to_owned();
        let subscript = field(b, 8, l2)?;
        let params = if pointer <= 0 {
            // An entity with no parameter data (some writers' null entities): nothing to read.
            Vec::new()
        } else {
            let start = pointer as usize - 1;
            if start >= p.len() {
                return Err(syntax(
                    l1,
                    format!(
                        "directory entry {de}: its parameters start at P line {pointer}, past the {} P lines",
                        p.len()
                    ),
                ));
            }
            // The parameter lines are those from `pointer` on that point back at this entry
            // (columns 65-72), whatever the directory's line count says; the fields end at the
            // first record delimiter outside a string. Every line names one entry, so each
            // line is read once however the directory points: a file whose entries all point
            // at one long parameter block costs that block once, not once per entry.
            let mut text = Vec::new();
            let mut n = 0;
            while start + n < p.len() {
                let (line_no, line) = p[start + n];
                let back = trim_int(&line[64..72]);
                if back != Some(de as i64) {
                    if n == 0 {
                        return Err(syntax(
                            line_no,
                            format!(
                                "directory entry {de} (type {ty}) points at P line {pointer}, which belongs to directory entry {} (columns 65-72)",
                                String::from_utf8_lossy(&line[64..72]).trim()
                            ),
                        ));
                    }
                    break;
                }
                text.extend_from_slice(&line[..64]);
                n += 1;
            }
            let line = p[start].0;
            let mut t = tokens(&text, pdelim, rdelim)
                .map_err(|m| syntax(line, format!("directory entry {de} (type {ty}): {m}")))?;
            let first = t.first().and_then(|t| match t {
                Token::Raw(s) => s.parse::<i64>().ok(),
                _ => None,
            });
            if first != Some(ty) {
                return Err(syntax(
                    line,
                    format!(
                        "directory entry {de} is of type {ty}, but its parameters start with {:?}",
                        t.first().unwrap_or(&Token::Empty)
                    ),
                ));
            }
            t.remove(0);
            t
        };
        entries.push(Entry {
            de,
            ty,
            form,
            transform,
            status,
            label,
            subscript,
            params,
        });
    }
    Ok(Iges {
        global: global.2,
        entries,
    })
}

/// Field `i` (0-based, 8 columns each) of a directory line as an integer; blank is 0.
fn field(line: &[u8], i: usize, line_no: usize) -> Result<i64> {
    let f = &line[8 * i..8 * i + 8];
    trim_int(f).ok_or_else(|| {
        syntax(
            line_no,
            format!(
                "directory field {} ({:?}) is not an integer",
                i + 1,
                String::from_utf8_lossy(f)
            ),
        )
    })
}

fn trim_int(f: &[u8]) -> Option<i64> {
    let s = String::from_utf8_lossy(f);
    let s = s.trim();
    if s.is_empty() {
        Some(0)
    } else {
        s.parse().ok()
    }
}

/// The status number (directory field 9): four pairs of digits, blanks read as 0.
fn status(line: &[u8], line_no: usize) -> Result<[u8; 4]> {
    let f = &line[64..72];
    let mut out = [0u8; 4];
    for (k, pair) in f.chunks(2).enumerate() {
        let mut v = 0u8;
        for &c in pair {
            let d = match c {
                b' ' => 0,
                b'0'..=b'9' => c - b'0',
                _ => {
                    return Err(syntax(
                        line_no,
                        format!(
                            "status number {:?} is not 8 digits",
                            String::from_utf8_lossy(f)
                        ),
                    ))
                }
            };
            v = v * 10 + d;
        }
        out[k] = v;
    }
    Ok(out)
}

/// The global section: (parameter delimiter, record delimiter, fields from the third on).
fn global(lines: &[(usize, &[u8])]) -> Result<(u8, u8, Vec<Token>)> {
    let line = lines[0].0;
    let text: Vec<u8> = lines
        .iter()
        .flat_map(|(_, l)| l[..72].iter().copied())
        .collect();
    let bad = |m: &str| syntax(line, format!("global section: {m}"));
    let mut i = 0;
    let skip = |i: &mut usize| {
        while *i < text.len() && text[*i] == b' ' {
            *i += 1;
        }
    };
    // Field 1: `1Hx` names the parameter delimiter; a field left empty means the comma.
    skip(&mut i);
    let pdelim = if text[i..].starts_with(b"1H") && i + 2 < text.len() {
        i += 3;
        text[i - 1]
    } else {
        b','
    };
    skip(&mut i);
    if text.get(i) != Some(&pdelim) {
        return Err(bad(
            "the parameter delimiter field is not followed by the delimiter",
        ));
    }
    i += 1;
    skip(&mut i);
    let rdelim = if text[i..].starts_with(b"1H") && i + 2 < text.len() {
        i += 3;
        text[i - 1]
    } else {
        b';'
    };
    if pdelim == rdelim || pdelim == b' ' || rdelim == b' ' {
        return Err(bad(
            "the parameter and record delimiters must be two different characters, not blanks",
        ));
    }
    skip(&mut i);
    match text.get(i) {
        Some(&c) if c == rdelim => Ok((pdelim, rdelim, Vec::new())),
        Some(&c) if c == pdelim => {
            let t = tokens(&text[i + 1..], pdelim, rdelim).map_err(|m| bad(&m))?;
            Ok((pdelim, rdelim, t))
        }
        _ => Err(bad(
            "the record delimiter field is not followed by a delimiter",
        )),
    }
}

/// The free-format fields of `s` up to the record delimiter.
pub(crate) fn tokens(s: &[u8], pd: u8, rd: u8) -> std::result::Result<Vec<Token>, String> {
    let mut out = Vec::new();
    let mut i = 0;
    loop {
        while i < s.len() && s[i] == b' ' {
            i += 1;
        }
        let mut j = i;
        while j < s.len() && s[j].is_ascii_digit() {
            j += 1;
        }
        if j > i && j < s.len() && (s[j] == b'H' || s[j] == b'h') {
            let n: usize = std::str::from_utf8(&s[i..j])
                .ok()
                .and_then(|d| d.parse().ok())
                .ok_or_else(|| "a string length that is not a number".to_string())?;
            let start = j + 1;
            if n > s.len() - start {
                return Err(format!(
                    "a string of {n} characters runs past the end of the entity's text ({} characters left)",
                    s.len() - start
                ));
            }
            out.push(Token::Text(
                String::from_utf8_lossy(&s[start..start + n]).into_owned(),
            ));
            i = start + n;
            while i < s.len() && s[i] == b' ' {
                i += 1;
            }
        } else {
            let mut k = i;
            while k < s.len() && s[k] != pd && s[k] != rd {
                k += 1;
            }
            let raw = String::from_utf8_lossy(&s[i..k]);
            let raw = raw.trim();
            out.push(if raw.is_empty() {
                Token::Empty
            } else {
                Token::Raw(raw.to_owned())
            });
            i = k;
        }
        match s.get(i) {
            None => return Err("no record delimiter ends the parameters".into()),
            Some(&c) if c == rd => return Ok(out),
            Some(&c) if c == pd => i += 1,
            Some(&c) => {
                return Err(format!(
                    "{:?} after a string, where a delimiter belongs",
                    c as char
                ))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_strings_and_defaults() {
        let t = tokens(b"126,3HA,B, 1.5D1,,-2;", b',', b';').expect("parses");
        assert_eq!(
            t,
            vec![
                Token::Raw("126".into()),
                Token::Text("A,B".into()),
                Token::Raw("1.5D1".into()),
                Token::Empty,
                Token::Raw("-2".into()),
            ],
            "a Hollerith keeps its delimiters; an empty field is the default"
        );
        assert!(
            tokens(b"9Habc;", b',', b';').is_err(),
            "a string past the end is refused"
        );
        assert!(tokens(b"1,2", b',', b';').is_err(), "no record delimiter");
    }
}
