//! Text that may reach a program.

use std::fmt;

/// The first character of a text that must not reach a program, with its position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TextDefect {
    /// The character.
    pub character: char,
    /// Its index among the characters of the text (from 0).
    pub index: usize,
}

impl fmt::Display for TextDefect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self.character {
            '\n' => " (line feed)",
            '\r' => " (carriage return)",
            '\t' => " (tab)",
            '\0' => " (NUL)",
            '\u{1b}' => " (escape)",
            '\u{7f}' => " (delete)",
            '\u{85}' => " (next line)",
            '\u{2028}' => " (line separator)",
            '\u{2029}' => " (paragraph separator)",
            _ => "",
        };
        write!(
            f,
            "contains the control character U+{:04X}{name} at character {}; ids and names \
             are written into G-code comments and must be one line of printable text",
            u32::from(self.character),
            self.index
        )
    }
}

/// Checks that `text` is one line of printable text: no C0 control (U+0000-U+001F, tab
/// included), no DEL, no C1 control (U+0080-U+009F, NEL included), no line or paragraph
/// separator (U+2028, U+2029).
///
/// These are the characters that end a line or a comment for some consumer of kerf's output
/// (a G-code controller ends a block at `\n` or `\r`, some at NUL; a terminal obeys ESC), so
/// an id holding one could add a block to a program.
///
/// # Errors
/// The first offending character and its position.
pub fn check_text(text: &str) -> Result<(), TextDefect> {
    match text
        .chars()
        .enumerate()
        .find(|&(_, c)| c.is_control() || c == '\u{2028}' || c == '\u{2029}')
    {
        Some((index, character)) => Err(TextDefect { character, index }),
        None => Ok(()),
    }
}

/// `x` with at most `places` decimals, trailing zeros and a trailing point dropped, `-0` as
/// `0`: a number for a human or a file that wants no noise (`0.031000000000000003` to 12
/// places is `0.031`, `2.50` to 2 is `2.5`). A non-finite `x` is written as Rust writes it
/// (`NaN`, `inf`).
pub fn decimal(x: f64, places: usize) -> String {
    let s = format!("{x:.places$}");
    if !x.is_finite() {
        return s;
    }
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimals_drop_their_noise_and_trailing_zeros_only() {
        assert_eq!(decimal(0.01 + 0.01 + 0.005 + 0.001 + 0.005, 12), "0.031");
        assert_eq!(decimal(2.5, 2), "2.5");
        assert_eq!(decimal(100.0, 2), "100", "zeros before the point stay");
        assert_eq!(decimal(120.0, 0), "120", "no point: nothing trimmed");
        assert_eq!(decimal(-0.001, 2), "0", "-0 is 0");
        assert_eq!(
            decimal(-1.25, 1),
            "-1.2",
            "rounded half to even as format! does"
        );
        assert_eq!(decimal(f64::NAN, 3), "NaN");
    }

    #[test]
    fn printable_text_passes() {
        for ok in ["hole", "Kante 3 (außen)", "孔-1", "a;b(c)", "é", ""] {
            assert_eq!(check_text(ok), Ok(()), "{ok:?}");
        }
    }

    #[test]
    fn every_line_breaking_or_control_character_is_refused() {
        let bad: Vec<char> = (0u32..0x20)
            .chain(0x7f..0xa0)
            .chain([0x2028, 0x2029])
            .filter_map(char::from_u32)
            .collect();
        assert_eq!(bad.len(), 32 + 33 + 2, "C0, DEL + C1, separators");
        for c in bad {
            let text = format!("ab{c}G0 X1");
            let e = check_text(&text).expect_err("refused");
            assert_eq!(
                e,
                TextDefect {
                    character: c,
                    index: 2
                },
                "{c:?}"
            );
        }
        let e = check_text("hole\nG0 X1400").expect_err("newline");
        assert!(e.to_string().contains("U+000A (line feed)"), "{e}");
    }
}
