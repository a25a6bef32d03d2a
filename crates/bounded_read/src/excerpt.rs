//! Text of an input file as an error message shows it: at most [`EXCERPT_CHARACTERS`] characters,
//! cut on a character boundary, with an ellipsis and the text's full length when cut. A message
//! about a 300 MB cell stays one short line, and the cell is never copied to make it.

/// The most characters of an input's text that a message shows.
pub const EXCERPT_CHARACTERS: usize = 80;

/// The start of `text` shown in a message: [`Display`](std::fmt::Display) quotes it as Rust
/// strings are quoted (`"a\nb"`); a text longer than [`EXCERPT_CHARACTERS`] characters shows its
/// first ones, an ellipsis and its length: `"abcabc…" (300000000 characters)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Excerpt<'a> {
    shown: &'a str,
    /// The length in characters of the whole text, when it is longer than `shown`.
    cut_from: Option<usize>,
}

impl<'a> Excerpt<'a> {
    /// The excerpt of `text`.
    pub fn of(text: &'a str) -> Self {
        match text.char_indices().nth(EXCERPT_CHARACTERS) {
            None => Self {
                shown: text,
                cut_from: None,
            },
            Some((boundary, _)) => Self {
                shown: &text[..boundary],
                cut_from: Some(EXCERPT_CHARACTERS + text[boundary..].chars().count()),
            },
        }
    }

    /// The excerpt without quotes, for a name inside a message that quotes it otherwise (a column
    /// name in `file:line:name:`): `abc` or `abcabc… (300000000 characters)`.
    pub fn unquoted(&self) -> String {
        match self.cut_from {
            None => self.shown.to_string(),
            Some(length) => format!("{}… ({length} characters)", self.shown),
        }
    }
}

impl std::fmt::Display for Excerpt<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.cut_from {
            None => write!(f, "{:?}", self.shown),
            Some(length) => {
                let quoted = format!("{:?}", self.shown);
                let open = &quoted[..quoted.len() - 1];
                write!(f, "{open}…\" ({length} characters)")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_text_is_quoted_whole() {
        assert_eq!(Excerpt::of("abc").to_string(), "\"abc\"");
        assert_eq!(Excerpt::of("a\"b\nc").to_string(), "\"a\\\"b\\nc\"");
        assert_eq!(Excerpt::of("").to_string(), "\"\"");
        let exact = "x".repeat(EXCERPT_CHARACTERS);
        assert_eq!(Excerpt::of(&exact).to_string(), format!("\"{exact}\""));
        assert_eq!(Excerpt::of("name").unquoted(), "name");
    }

    #[test]
    fn long_text_is_cut_on_a_character_boundary_with_its_length() {
        let text = "abc".repeat(1000);
        let shown = Excerpt::of(&text).to_string();
        assert_eq!(
            shown,
            format!("\"{}…\" (3000 characters)", &text[..EXCERPT_CHARACTERS])
        );
        // Two-byte and four-byte characters: never cut inside one, the length in characters.
        let text = "é🦀".repeat(100);
        let excerpt = Excerpt::of(&text);
        let expected: String = text.chars().take(EXCERPT_CHARACTERS).collect();
        assert_eq!(
            excerpt.to_string(),
            format!("\"{expected}…\" (200 characters)")
        );
        assert_eq!(excerpt.unquoted(), format!("{expected}… (200 characters)"));
    }
}
