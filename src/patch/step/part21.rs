//! A small ISO 10303-21 ("STEP Part 21") reader: the DATA section as a map from `#id` to its
//! entity, simple (`#5=CIRCLE('',#7,2.);`) or complex (`#6=(A(..) B(..));`).
//!
//! Written here rather than taken from `ruststep`: the B-rep reader needs only the instance
//! graph (no schema types), and the whole tokenizer and parser are a few hundred lines with a
//! byte cap, an entity cap and a nesting cap, so hostile input cannot ask for large
//! allocations or deep recursion. Errors are [`StepError`]s, one line each, with the 1-based
//! line number.

use std::collections::HashMap;

use super::StepError;

/// Largest file accepted (bytes). The paper's largest model is under 1 MB; CAD assemblies
/// of a few hundred MB exist, but those are far beyond what the patch evaluator serves.
pub const MAX_BYTES: usize = 256 << 20;
/// Largest number of entity instances accepted.
pub const MAX_ENTITIES: usize = 4_000_000;
/// Deepest nesting of parameter lists (B-spline weights are two levels; 16 is generous and
/// bounds the parser's recursion).
pub const MAX_NESTING: usize = 16;

/// A parameter value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// An integer (knot multiplicities, degrees).
    Int(i64),
    /// A real number.
    Real(f64),
    /// A string (quotes removed, `''` unescaped; `\X\` escapes are kept as written).
    Str(String),
    /// An enumeration value without the dots (`.T.` → `T`).
    Enum(String),
    /// A reference `#id`.
    Ref(u64),
    /// A list `( … )`.
    List(Vec<Value>),
    /// A typed parameter `NAME( … )`, e.g. `LENGTH_MEASURE(1.E-3)`.
    Typed(String, Vec<Value>),
    /// `$`: no value.
    Null,
    /// `*`: a value derived from a supertype.
    Derived,
}

/// One partial entity: its (upper-case) name and parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Entity name.
    pub name: String,
    /// Parameters in file order.
    pub params: Vec<Value>,
}

/// An entity instance: one part for a simple entity, several for a complex one.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// The parts (a complex entity lists its supertypes and subtypes, in file order).
    pub parts: Vec<Part>,
    /// 1-based line of the `#id=`.
    pub line: usize,
}

impl Instance {
    /// The part named `name`, if any.
    pub fn part(&self, name: &str) -> Option<&Part> {
        self.parts.iter().find(|p| p.name == name)
    }

    /// A name for messages: the simple entity's name, or `(A B …)` for a complex one.
    pub fn display_name(&self) -> String {
        if self.parts.len() == 1 {
            self.parts[0].name.clone()
        } else {
            let names: Vec<&str> = self.parts.iter().map(|p| p.name.as_str()).collect();
            format!("({})", names.join(" "))
        }
    }
}

/// The DATA section of a Part 21 file.
#[derive(Clone, Debug, Default)]
pub struct Part21 {
    /// Instances by id.
    pub instances: HashMap<u64, Instance>,
    /// Ids in file order (for deterministic iteration).
    pub order: Vec<u64>,
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Keyword(String),
    Ref(u64),
    Int(i64),
    Real(f64),
    Str(String),
    Enum(String),
    Dollar,
    Star,
    Open,
    Close,
    Comma,
    Equals,
    Semicolon,
}

struct Lexer<'a> {
    s: &'a [u8],
    pos: usize,
    line: usize,
}

fn syntax(line: usize, message: impl Into<String>) -> StepError {
    StepError::Syntax {
        line,
        message: message.into(),
    }
}

impl<'a> Lexer<'a> {
    fn skip_space(&mut self) -> Result<(), StepError> {
        loop {
            match self.s.get(self.pos) {
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(c) if c.is_ascii_whitespace() => self.pos += 1,
                Some(b'/') if self.s.get(self.pos + 1) == Some(&b'*') => {
                    let start = self.line;
                    self.pos += 2;
                    loop {
                        match self.s.get(self.pos) {
                            None => return Err(syntax(start, "unterminated comment")),
                            Some(b'*') if self.s.get(self.pos + 1) == Some(&b'/') => {
                                self.pos += 2;
                                break;
                            }
                            Some(b'\n') => {
                                self.line += 1;
                                self.pos += 1;
                            }
                            _ => self.pos += 1,
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    /// The next token and the line it starts on; `None` at the end of the input.
    fn next(&mut self) -> Result<Option<(Token, usize)>, StepError> {
        self.skip_space()?;
        let line = self.line;
        let Some(&c) = self.s.get(self.pos) else {
            return Ok(None);
        };
        let single = |t: Token| Ok(Some((t, line)));
        match c {
            b'(' => {
                self.pos += 1;
                single(Token::Open)
            }
            b')' => {
                self.pos += 1;
                single(Token::Close)
            }
            b',' => {
                self.pos += 1;
                single(Token::Comma)
            }
            b'=' => {
                self.pos += 1;
                single(Token::Equals)
            }
            b';' => {
                self.pos += 1;
                single(Token::Semicolon)
            }
            b'$' => {
                self.pos += 1;
                single(Token::Dollar)
            }
            b'*' => {
                self.pos += 1;
                single(Token::Star)
            }
            b'#' => {
                self.pos += 1;
                let start = self.pos;
                while self.s.get(self.pos).is_some_and(u8::is_ascii_digit) {
                    self.pos += 1;
                }
                let text = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
                let id = text
                    .parse::<u64>()
                    .map_err(|_| syntax(line, "`#` not followed by an instance number"))?;
                single(Token::Ref(id))
            }
            b'\'' => {
                self.pos += 1;
                let mut out = Vec::new();
                loop {
                    match self.s.get(self.pos) {
                        None => return Err(syntax(line, "unterminated string")),
                        Some(b'\'') if self.s.get(self.pos + 1) == Some(&b'\'') => {
                            out.push(b'\'');
                            self.pos += 2;
                        }
                        Some(b'\'') => {
                            self.pos += 1;
                            break;
                        }
                        Some(&ch) => {
                            if ch == b'\n' {
                                self.line += 1;
                            }
                            out.push(ch);
                            self.pos += 1;
                        }
                    }
                }
                single(Token::Str(String::from_utf8_lossy(&out).into_owned()))
            }
            b'"' => {
                // Binary literal: kept as text (not used by the B-rep reader).
                self.pos += 1;
                let start = self.pos;
                while let Some(&ch) = self.s.get(self.pos) {
                    if ch == b'"' {
                        break;
                    }
                    self.pos += 1;
                }
                if self.pos >= self.s.len() {
                    return Err(syntax(line, "unterminated binary literal"));
                }
                let text = String::from_utf8_lossy(&self.s[start..self.pos]).into_owned();
                self.pos += 1;
                single(Token::Str(text))
            }
            b'.' if self
                .s
                .get(self.pos + 1)
                .is_some_and(|ch| ch.is_ascii_alphabetic() || *ch == b'_') =>
            {
                self.pos += 1;
                let start = self.pos;
                while self
                    .s
                    .get(self.pos)
                    .is_some_and(|ch| ch.is_ascii_alphanumeric() || *ch == b'_')
                {
                    self.pos += 1;
                }
                if self.s.get(self.pos) != Some(&b'.') {
                    return Err(syntax(line, "enumeration value without closing `.`"));
                }
                let text = String::from_utf8_lossy(&self.s[start..self.pos]).to_ascii_uppercase();
                self.pos += 1;
                single(Token::Enum(text))
            }
            b'+' | b'-' | b'.' | b'0'..=b'9' => {
                let start = self.pos;
                self.pos += 1;
                while self.s.get(self.pos).is_some_and(|ch| {
                    ch.is_ascii_digit() || matches!(ch, b'.' | b'e' | b'E' | b'+' | b'-')
                }) {
                    // A sign is part of the number only right after an exponent marker.
                    let ch = self.s[self.pos];
                    if matches!(ch, b'+' | b'-') && !matches!(self.s[self.pos - 1], b'e' | b'E') {
                        break;
                    }
                    self.pos += 1;
                }
                let text = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
                let is_real = text.contains(['.', 'e', 'E']);
                if is_real {
                    // Part 21 allows `1.E-3` and `1.`; Rust's parser accepts both.
                    let v = text
                        .parse::<f64>()
                        .map_err(|_| syntax(line, format!("bad real number `{text}`")))?;
                    single(Token::Real(v))
                } else {
                    let v = text
                        .parse::<i64>()
                        .map_err(|_| syntax(line, format!("bad integer `{text}`")))?;
                    single(Token::Int(v))
                }
            }
            c if c.is_ascii_alphabetic() || c == b'_' || c == b'!' => {
                let start = self.pos;
                self.pos += 1;
                while self
                    .s
                    .get(self.pos)
                    .is_some_and(|ch| ch.is_ascii_alphanumeric() || *ch == b'_' || *ch == b'-')
                {
                    self.pos += 1;
                }
                let text = String::from_utf8_lossy(&self.s[start..self.pos]).to_ascii_uppercase();
                single(Token::Keyword(text))
            }
            other => Err(syntax(
                line,
                format!("unexpected character `{}`", other.escape_ascii()),
            )),
        }
    }
}

struct Parser<'a> {
    lex: Lexer<'a>,
    peeked: Option<(Token, usize)>,
}

impl<'a> Parser<'a> {
    fn peek(&mut self) -> Result<Option<&(Token, usize)>, StepError> {
        if self.peeked.is_none() {
            self.peeked = self.lex.next()?;
        }
        Ok(self.peeked.as_ref())
    }

    fn bump(&mut self) -> Result<Option<(Token, usize)>, StepError> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        self.lex.next()
    }

    fn expect(&mut self, want: Token, what: &str) -> Result<usize, StepError> {
        match self.bump()? {
            Some((t, line)) if t == want => Ok(line),
            Some((t, line)) => Err(syntax(line, format!("expected {what}, found {t:?}"))),
            None => Err(syntax(self.lex.line, format!("expected {what}, file ends"))),
        }
    }

    /// `( v, v, … )` after the opening parenthesis has been read.
    fn list_rest(&mut self, depth: usize) -> Result<Vec<Value>, StepError> {
        if depth > MAX_NESTING {
            return Err(syntax(
                self.lex.line,
                format!("parameter lists nested deeper than {MAX_NESTING}"),
            ));
        }
        let mut out = Vec::new();
        if matches!(self.peek()?, Some((Token::Close, _))) {
            self.bump()?;
            return Ok(out);
        }
        loop {
            out.push(self.value(depth)?);
            match self.bump()? {
                Some((Token::Comma, _)) => {}
                Some((Token::Close, _)) => return Ok(out),
                Some((t, line)) => {
                    return Err(syntax(line, format!("expected `,` or `)`, found {t:?}")));
                }
                None => return Err(syntax(self.lex.line, "file ends inside a parameter list")),
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Value, StepError> {
        let Some((t, line)) = self.bump()? else {
            return Err(syntax(self.lex.line, "file ends inside a parameter list"));
        };
        Ok(match t {
            Token::Int(i) => Value::Int(i),
            Token::Real(r) => Value::Real(r),
            Token::Str(s) => Value::Str(s),
            Token::Enum(e) => Value::Enum(e),
            Token::Ref(r) => Value::Ref(r),
            Token::Dollar => Value::Null,
            Token::Star => Value::Derived,
            Token::Open => Value::List(self.list_rest(depth + 1)?),
            Token::Keyword(k) => {
                self.expect(Token::Open, "`(` after a typed parameter")?;
                Value::Typed(k, self.list_rest(depth + 1)?)
            }
            other => return Err(syntax(line, format!("unexpected {other:?} in parameters"))),
        })
    }

    /// `NAME( … )` (the name already read).
    fn part(&mut self, name: String) -> Result<Part, StepError> {
        self.expect(Token::Open, "`(` after an entity name")?;
        let params = self.list_rest(1)?;
        Ok(Part { name, params })
    }
}

/// Parses Part 21 text. Only the DATA section(s) are kept; the HEADER is checked for syntax.
pub fn parse(text: &str) -> Result<Part21, StepError> {
    if text.len() > MAX_BYTES {
        return Err(StepError::TooLarge(format!(
            "{} bytes, more than the {} accepted",
            text.len(),
            MAX_BYTES
        )));
    }
    let mut p = Parser {
        lex: Lexer {
            s: text.as_bytes(),
            pos: 0,
            line: 1,
        },
        peeked: None,
    };
    match p.bump()? {
        Some((Token::Keyword(k), _)) if k == "ISO-10303-21" => {}
        Some((_, line)) => return Err(syntax(line, "not a STEP file (no `ISO-10303-21;`)")),
        None => return Err(syntax(1, "empty file")),
    }
    p.expect(Token::Semicolon, "`;` after ISO-10303-21")?;
    let mut out = Part21::default();
    let mut in_data = false;
    let mut saw_end = false;
    let mut saw_data = false;
    while let Some((t, line)) = p.bump()? {
        match t {
            Token::Keyword(k) if k == "END-ISO-10303-21" => {
                p.expect(Token::Semicolon, "`;` after END-ISO-10303-21")?;
                saw_end = true;
                break;
            }
            Token::Keyword(k) if k == "HEADER" => {
                p.expect(Token::Semicolon, "`;` after HEADER")?;
            }
            Token::Keyword(k) if k == "DATA" => {
                // `DATA;` or (edition 3) `DATA('name', (schemas));`
                if matches!(p.peek()?, Some((Token::Open, _))) {
                    p.bump()?;
                    p.list_rest(1)?;
                }
                p.expect(Token::Semicolon, "`;` after DATA")?;
                in_data = true;
                saw_data = true;
            }
            Token::Keyword(k) if k == "ENDSEC" => {
                p.expect(Token::Semicolon, "`;` after ENDSEC")?;
                in_data = false;
            }
            Token::Keyword(k) if !in_data => {
                // Header entities: FILE_DESCRIPTION(...); etc.
                p.part(k)?;
                p.expect(Token::Semicolon, "`;` after a header entity")?;
            }
            Token::Ref(id) if in_data => {
                p.expect(Token::Equals, "`=` after an instance number")?;
                let parts = match p.bump()? {
                    Some((Token::Keyword(name), _)) => vec![p.part(name)?],
                    Some((Token::Open, _)) => {
                        let mut parts = Vec::new();
                        loop {
                            match p.bump()? {
                                Some((Token::Keyword(name), _)) => parts.push(p.part(name)?),
                                Some((Token::Close, _)) => break,
                                Some((t, l)) => {
                                    return Err(syntax(
                                        l,
                                        format!("expected an entity name in #{id}, found {t:?}"),
                                    ));
                                }
                                None => return Err(syntax(line, format!("#{id}: file ends"))),
                            }
                        }
                        if parts.is_empty() {
                            return Err(syntax(line, format!("#{id}: empty complex entity")));
                        }
                        parts
                    }
                    Some((t, l)) => {
                        return Err(syntax(l, format!("#{id}: expected an entity, found {t:?}")));
                    }
                    None => return Err(syntax(line, format!("#{id}: file ends"))),
                };
                p.expect(Token::Semicolon, "`;` after an entity instance")?;
                if out.instances.len() >= MAX_ENTITIES {
                    return Err(StepError::TooLarge(format!(
                        "more than {MAX_ENTITIES} entity instances"
                    )));
                }
                if out.instances.insert(id, Instance { parts, line }).is_some() {
                    return Err(syntax(line, format!("#{id} is defined twice")));
                }
                out.order.push(id);
            }
            other => {
                return Err(syntax(line, format!("unexpected {other:?}")));
            }
        }
    }
    if !saw_data {
        return Err(syntax(p.lex.line, "no DATA section"));
    }
    if !saw_end {
        return Err(syntax(
            p.lex.line,
            "file ends without END-ISO-10303-21; (truncated?)",
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "ISO-10303-21;\nHEADER;\nFILE_NAME('a''b',(''),$);\nENDSEC;\nDATA;\n\
        /* c */ #1=CARTESIAN_POINT('',(1.,-2.5E-1,3));\n#2=(A(1,$) B(.T.,*,(#1,#3)));\n\
        #3=X(LENGTH_MEASURE(1.E-3),'it''s');\nENDSEC;\nEND-ISO-10303-21;\n";

    #[test]
    fn parses_simple_complex_and_typed_values() {
        let f = parse(SMALL).unwrap();
        assert_eq!(f.order, vec![1, 2, 3]);
        let p = &f.instances[&1].parts[0];
        assert_eq!(p.name, "CARTESIAN_POINT");
        assert_eq!(
            p.params[1],
            Value::List(vec![Value::Real(1.0), Value::Real(-0.25), Value::Int(3)])
        );
        let c = &f.instances[&2];
        assert_eq!(c.display_name(), "(A B)");
        assert_eq!(c.part("B").unwrap().params[0], Value::Enum("T".into()));
        assert_eq!(c.part("B").unwrap().params[1], Value::Derived);
        assert_eq!(
            f.instances[&3].parts[0].params,
            vec![
                Value::Typed("LENGTH_MEASURE".into(), vec![Value::Real(1e-3)]),
                Value::Str("it's".into())
            ]
        );
        assert_eq!(f.instances[&3].line, 8);
    }

    #[test]
    fn malformed_input_is_a_one_line_error() {
        let cut = &SMALL[..SMALL.len() - 30];
        for bad in [
            "",
            "HELLO;",
            cut,
            "ISO-10303-21;\nDATA;\n#1=A(1;\nENDSEC;\nEND-ISO-10303-21;",
            "ISO-10303-21;\nDATA;\n#1=A(1);\n#1=B(2);\nENDSEC;\nEND-ISO-10303-21;",
            "ISO-10303-21;\nDATA;\n#1=A('x);\nENDSEC;\nEND-ISO-10303-21;",
            "ISO-10303-21;\nDATA;\n#1=A(((((((((((((((((((1))))))))))))))))));\nENDSEC;\nEND-ISO-10303-21;",
            "ISO-10303-21;\nDATA;\n#=A(1);\nENDSEC;\nEND-ISO-10303-21;",
            "ISO-10303-21;\nDATA;\n#1=A(1e999999999999999999x);\nENDSEC;\nEND-ISO-10303-21;",
        ] {
            let e = parse(bad).unwrap_err().to_string();
            assert!(!e.contains('\n') && !e.is_empty(), "{e}");
        }
    }
}
