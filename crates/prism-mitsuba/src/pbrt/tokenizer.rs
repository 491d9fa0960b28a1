//! pbrt-v4's tokens (pbrt-v4's `Tokenizer`, `src/pbrt/parser.cpp`): words (directive names,
//! numbers, `true`/`false`), quoted strings with the escapes `\b \f \n \r \t \\ \' \"`, and the
//! brackets `[` and `]`; whitespace separates tokens and `#` starts a comment that runs to the
//! end of the line. A string may not span lines. Every token keeps the file, line and column of
//! its first character (columns count characters from 1).

use std::path::Path;
use std::sync::Arc;

use prism_core::error::{Error, Result, SourceLocation};

/// What a token is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokenKind {
    /// A directive name, a number or a bare `true`/`false`.
    Word,
    /// A quoted string; the token's text is its contents with escapes resolved.
    Quoted,
    /// `[`
    Open,
    /// `]`
    Close,
}

/// One token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub kind: TokenKind,
    pub text: String,
    pub location: SourceLocation,
}

/// Splits the text of one file into tokens, one at a time.
pub struct Tokenizer<'a> {
    text: &'a str,
    /// Byte offset of the next character.
    position: usize,
    line: u32,
    column: u32,
    file: Arc<Path>,
}

impl<'a> Tokenizer<'a> {
    /// Tokens of `text`, whose locations name `file`.
    pub fn new(text: &'a str, file: &Path) -> Self {
        Tokenizer {
            text,
            position: 0,
            line: 1,
            column: 1,
            file: Arc::from(file),
        }
    }

    fn location(&self) -> SourceLocation {
        SourceLocation {
            file: self.file.clone(),
            line: self.line,
            column: self.column,
        }
    }

    fn peek_char(&self) -> Option<char> {
        self.text[self.position..].chars().next()
    }

    fn advance(&mut self) -> Option<char> {
        let c = self.peek_char()?;
        self.position += c.len_utf8();
        if c == '\n' {
            self.line += 1;
            self.column = 1;
        } else {
            self.column += 1;
        }
        Some(c)
    }

    /// The next token, or `None` at the end of the text.
    pub fn next_token(&mut self) -> Result<Option<Token>> {
        loop {
            match self.peek_char() {
                None => return Ok(None),
                Some(c) if c.is_whitespace() => {
                    self.advance();
                }
                Some('#') => {
                    while let Some(c) = self.advance() {
                        if c == '\n' {
                            break;
                        }
                    }
                }
                Some(_) => break,
            }
        }
        let location = self.location();
        let token = |kind, text: String| {
            Ok(Some(Token {
                kind,
                text,
                location: location.clone(),
            }))
        };
        match self.advance() {
            Some('[') => token(TokenKind::Open, "[".into()),
            Some(']') => token(TokenKind::Close, "]".into()),
            Some('"') => {
                let text = self.quoted(&location)?;
                token(TokenKind::Quoted, text)
            }
            Some(first) => {
                let mut text = String::from(first);
                while let Some(c) = self.peek_char() {
                    if c.is_whitespace() || matches!(c, '"' | '[' | ']' | '#') {
                        break;
                    }
                    text.push(c);
                    self.advance();
                }
                token(TokenKind::Word, text)
            }
            None => Ok(None),
        }
    }

    /// The rest of a string whose opening quote has been read.
    fn quoted(&mut self, start: &SourceLocation) -> Result<String> {
        let unterminated = || {
            Error::input(start, "unterminated string")
                .with_help("close the string with \" on the same line")
        };
        let mut text = String::new();
        loop {
            match self.advance() {
                None | Some('\n') => return Err(unterminated()),
                Some('"') => return Ok(text),
                Some('\\') => {
                    let escape = self.location();
                    let resolved = match self.advance() {
                        None | Some('\n') => return Err(unterminated()),
                        Some('b') => '\u{8}',
                        Some('f') => '\u{c}',
                        Some('n') => '\n',
                        Some('r') => '\r',
                        Some('t') => '\t',
                        Some(c @ ('\\' | '\'' | '"')) => c,
                        Some(c) => {
                            return Err(Error::input(
                                &escape,
                                format!("unknown escape sequence \"\\{c}\" in a string"),
                            )
                            .with_help("the escapes are \\b \\f \\n \\r \\t \\\\ \\' \\\""));
                        }
                    };
                    text.push(resolved);
                }
                Some(c) => text.push(c),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Result<Vec<(TokenKind, String, u32, u32)>> {
        let mut tokenizer = Tokenizer::new(text, Path::new("t.pbrt"));
        let mut all = Vec::new();
        while let Some(token) = tokenizer.next_token()? {
            all.push((
                token.kind,
                token.text,
                token.location.line,
                token.location.column,
            ));
        }
        Ok(all)
    }

    #[test]
    fn words_strings_brackets_and_comments() {
        let text = "Shape \"sphere\" # a comment \"not a string\"\n  \"float radius\" [2.5 -1e-3]";
        let found = tokens(text).unwrap();
        use TokenKind::*;
        assert_eq!(
            found,
            vec![
                (Word, "Shape".into(), 1, 1),
                (Quoted, "sphere".into(), 1, 7),
                (Quoted, "float radius".into(), 2, 3),
                (Open, "[".into(), 2, 18),
                (Word, "2.5".into(), 2, 19),
                (Word, "-1e-3".into(), 2, 23),
                (Close, "]".into(), 2, 28),
            ]
        );
    }

    #[test]
    fn brackets_and_quotes_end_words() {
        let found = tokens("[1 2]\"a\"x#c").unwrap();
        let texts: Vec<&str> = found.iter().map(|t| t.1.as_str()).collect();
        assert_eq!(texts, ["[", "1", "2", "]", "a", "x"]);
    }

    #[test]
    fn escapes_are_resolved() {
        let found = tokens(r#""a\"b\\c\td\n""#).unwrap();
        assert_eq!(found[0].1, "a\"b\\c\td\n");
    }

    #[test]
    fn columns_count_characters() {
        let found = tokens("\"λ\" x").unwrap();
        assert_eq!((found[1].2, found[1].3), (1, 5));
    }

    #[test]
    fn an_unterminated_string_is_reported_where_it_starts() {
        for text in ["Shape \"sphere", "Shape \"sph\nere\""] {
            let error = tokens(text).unwrap_err();
            let location = error.location.unwrap();
            assert_eq!((location.line, location.column), (1, 7), "{text}");
            assert!(error.message.contains("unterminated string"), "{text}");
        }
    }

    #[test]
    fn an_unknown_escape_is_an_error() {
        let error = tokens("\"a\\q\"").unwrap_err();
        assert!(error.message.contains("\\q"), "{}", error.message);
        assert_eq!(error.location.unwrap().column, 4);
    }
}
