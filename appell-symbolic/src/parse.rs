//! A small infix syntax, so tests and docs read like math.
//!
//! ```text
//! expr  := term (('+' | '-') term)*
//! term  := unary (('*' | '/') unary)*
//! unary := '-' unary | power
//! power := atom ('^' unary)?          exponent: an integer, or n/2 (a root)
//! atom  := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! ```
//!
//! Numbers without `.` or exponent are exact integers; `1/3` is the exact
//! fraction. Functions: `sin cos tan exp ln abs sqrt atan2`.

use crate::error::{Result, SymbolicError};
use crate::graph::{Func, Graph, Id, SymbolKind};
use crate::number::Number;

/// How the parser treats names that are not declared symbols.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnknownNames {
    /// Declare them as [`SymbolKind::Auxiliary`].
    Declare,
    /// Report [`SymbolicError::UnknownSymbol`].
    Reject,
}

impl Graph {
    /// Parses an expression; unknown names become auxiliary symbols.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let one = g.parse("sin(x)^2 + cos(x)^2").unwrap();
    /// assert_eq!(g.as_number(one).unwrap().to_f64(), 1.0);
    /// ```
    pub fn parse(&mut self, text: &str) -> Result<Id> {
        self.parse_with(text, UnknownNames::Declare)
    }

    /// Parses an expression whose names must all be declared already.
    ///
    /// ```
    /// use appell_symbolic::{Graph, SymbolicError};
    /// let mut g = Graph::new();
    /// g.parameter("m").unwrap();
    /// assert!(g.parse_strict("2*m").is_ok());
    /// assert_eq!(
    ///     g.parse_strict("2*n"),
    ///     Err(SymbolicError::UnknownSymbol { name: "n".into() })
    /// );
    /// ```
    pub fn parse_strict(&mut self, text: &str) -> Result<Id> {
        self.parse_with(text, UnknownNames::Reject)
    }

    /// Parses with the given treatment of unknown names.
    pub fn parse_with(&mut self, text: &str, unknown: UnknownNames) -> Result<Id> {
        let mut p = Parser {
            src: text,
            pos: 0,
            graph: self,
            unknown,
        };
        let e = p.expr()?;
        p.skip_ws();
        if p.pos != p.src.len() {
            return Err(p.error("unexpected trailing input"));
        }
        Ok(e)
    }
}

struct Parser<'s, 'g> {
    src: &'s str,
    pos: usize,
    graph: &'g mut Graph,
    unknown: UnknownNames,
}

impl Parser<'_, '_> {
    fn error(&self, message: &str) -> SymbolicError {
        let found = self.src[self.pos..].chars().next();
        SymbolicError::Parse {
            position: self.pos,
            message: match found {
                Some(c) => format!("{message} (found `{c}`)"),
                None => format!("{message} (found end of input)"),
            },
        }
    }

    fn skip_ws(&mut self) {
        while let Some(c) = self.src[self.pos..].chars().next() {
            if c.is_whitespace() {
                self.pos += c.len_utf8();
            } else {
                break;
            }
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_ws();
        self.src[self.pos..].chars().next()
    }

    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(c) {
            self.pos += c.len_utf8();
            true
        } else {
            false
        }
    }

    fn expr(&mut self) -> Result<Id> {
        let mut parts = vec![(self.term()?, Number::ONE)];
        loop {
            if self.eat('+') {
                parts.push((self.term()?, Number::ONE));
            } else if self.eat('-') {
                parts.push((self.term()?, Number::MINUS_ONE));
            } else {
                break;
            }
        }
        if parts.len() == 1 {
            return Ok(parts[0].0);
        }
        self.graph.linear_combination(Number::ZERO, parts)
    }

    fn term(&mut self) -> Result<Id> {
        let mut acc = self.unary()?;
        loop {
            if self.eat('*') {
                let r = self.unary()?;
                acc = self.graph.mul(acc, r)?;
            } else if self.eat('/') {
                let r = self.unary()?;
                acc = self.graph.div(acc, r)?;
            } else {
                return Ok(acc);
            }
        }
    }

    fn unary(&mut self) -> Result<Id> {
        if self.eat('-') {
            let a = self.unary()?;
            return self.graph.neg(a);
        }
        self.power()
    }

    fn power(&mut self) -> Result<Id> {
        let base = self.atom()?;
        if !self.eat('^') {
            return Ok(base);
        }
        let at = self.pos;
        let e = self.unary()?;
        let bad = || SymbolicError::Parse {
            position: at,
            message: "the exponent must be an integer or a half-integer constant".to_string(),
        };
        match self.graph.as_number(e) {
            Some(Number::Rational { num, den: 1 }) => self
                .graph
                .powi(base, i64::try_from(num).map_err(|_| bad())?),
            Some(Number::Rational { num, den: 2 }) => {
                let root = self.graph.sqrt(base)?;
                self.graph
                    .powi(root, i64::try_from(num).map_err(|_| bad())?)
            }
            _ => Err(bad()),
        }
    }

    fn atom(&mut self) -> Result<Id> {
        match self.peek() {
            Some('(') => {
                self.pos += 1;
                let e = self.expr()?;
                if !self.eat(')') {
                    return Err(self.error("expected `)`"));
                }
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number(),
            Some(c) if c.is_alphabetic() || c == '_' => self.name(),
            _ => Err(self.error("expected a number, a name or `(`")),
        }
    }

    fn number(&mut self) -> Result<Id> {
        let start = self.pos;
        let bytes = self.src.as_bytes();
        let mut float = false;
        while self.pos < bytes.len() {
            let c = bytes[self.pos];
            if c.is_ascii_digit() {
                self.pos += 1;
            } else if c == b'.' {
                float = true;
                self.pos += 1;
            } else if (c == b'e' || c == b'E') && self.pos > start {
                float = true;
                self.pos += 1;
                if self.pos < bytes.len() && (bytes[self.pos] == b'-' || bytes[self.pos] == b'+') {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
        let text = &self.src[start..self.pos];
        let err = || SymbolicError::Parse {
            position: start,
            message: format!("malformed number `{text}`"),
        };
        if float {
            let x: f64 = text.parse().map_err(|_| err())?;
            self.graph.float(x)
        } else {
            let n: i128 = text.parse().map_err(|_| err())?;
            self.graph.num(Number::ratio(n, 1).ok_or_else(err)?)
        }
    }

    fn name(&mut self) -> Result<Id> {
        let start = self.pos;
        while let Some(c) = self.src[self.pos..].chars().next() {
            if c.is_alphanumeric() || c == '_' {
                self.pos += c.len_utf8();
            } else {
                break;
            }
        }
        let name = &self.src[start..self.pos];
        if self.peek() == Some('(') {
            self.pos += 1;
            let mut args = vec![self.expr()?];
            while self.eat(',') {
                args.push(self.expr()?);
            }
            if !self.eat(')') {
                return Err(self.error("expected `)` after the arguments"));
            }
            let arity_error = |n: usize| SymbolicError::Parse {
                position: start,
                message: format!("`{name}` takes {n} argument(s)"),
            };
            match (name, args.len()) {
                ("atan2", 2) => return self.graph.atan2(args[0], args[1]),
                ("powf", 2) => return self.graph.powf(args[0], args[1]),
                ("min", 2) => return self.graph.min(args[0], args[1]),
                ("max", 2) => return self.graph.max(args[0], args[1]),
                ("select", 3) => return self.graph.select(args[0], args[1], args[2]),
                ("atan2" | "powf" | "min" | "max", _) => return Err(arity_error(2)),
                ("select", _) => return Err(arity_error(3)),
                _ => {}
            }
            let Some(func) = Func::from_name(name) else {
                return Err(SymbolicError::Parse {
                    position: start,
                    message: format!("unknown function `{name}`"),
                });
            };
            if args.len() != 1 {
                return Err(arity_error(1));
            }
            return self.graph.func(func, args[0]);
        }
        let symbol = match self.graph.symbol_named(name) {
            Some(s) => s,
            None => match self.unknown {
                UnknownNames::Declare => self.graph.declare(name, SymbolKind::Auxiliary)?,
                UnknownNames::Reject => {
                    return Err(SymbolicError::UnknownSymbol {
                        name: name.to_string(),
                    })
                }
            },
        };
        self.graph.sym(symbol)
    }
}

#[cfg(test)]
mod tests {
    use crate::{Graph, SymbolicError};

    #[test]
    fn precedence() {
        let mut g = Graph::new();
        let a = g.parse("1 + 2*3^2").unwrap();
        assert_eq!(g.as_number(a).unwrap().to_f64(), 19.0);
    }
    #[test]
    fn unary_minus_binds_looser_than_power() {
        let mut g = Graph::new();
        let a = g.parse("-2^2").unwrap();
        assert_eq!(g.as_number(a).unwrap().to_f64(), -4.0);
    }
    #[test]
    fn half_exponent_is_sqrt() {
        let mut g = Graph::new();
        let a = g.parse("x^(3/2)").unwrap();
        let b = g.parse("x*sqrt(x)").unwrap();
        assert_eq!(a, b);
    }
    #[test]
    fn floats_and_exponents() {
        let mut g = Graph::new();
        let a = g.parse("1.5e-3").unwrap();
        assert_eq!(g.as_number(a).unwrap().to_f64(), 1.5e-3);
    }
    #[test]
    fn trailing_garbage() {
        let mut g = Graph::new();
        assert!(matches!(g.parse("x + )"), Err(SymbolicError::Parse { .. })));
    }
    #[test]
    fn unknown_function() {
        let mut g = Graph::new();
        assert!(matches!(
            g.parse("foo(x)"),
            Err(SymbolicError::Parse { .. })
        ));
    }
    #[test]
    fn wrong_arity() {
        let mut g = Graph::new();
        assert!(matches!(
            g.parse("atan2(x)"),
            Err(SymbolicError::Parse { .. })
        ));
    }
    #[test]
    fn symbolic_exponent_rejected() {
        let mut g = Graph::new();
        assert!(matches!(g.parse("x^y"), Err(SymbolicError::Parse { .. })));
    }
}
