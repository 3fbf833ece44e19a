//! Readable infix text of expressions. The output parses back (with
//! [`Graph::parse`]) to the same node, which the property tests check.

use std::fmt::{self, Write};

use crate::graph::{Func, Graph, Id, Node};
use crate::number::Number;

/// An expression together with its graph, for formatting.
///
/// ```
/// use appell_symbolic::Graph;
/// let mut g = Graph::new();
/// let e = g.parse("2*x*sin(y)/z^2 - x^2/3 + 1").unwrap();
/// assert_eq!(g.display(e).to_string(), "2*x*sin(y)/z^2 - 1/3*x^2 + 1");
/// ```
pub struct DisplayExpr<'a> {
    graph: &'a Graph,
    id: Id,
}

impl Graph {
    /// A formatter for `id`.
    pub fn display(&self, id: Id) -> DisplayExpr<'_> {
        DisplayExpr { graph: self, id }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum = 1,
    Product = 2,
    Power = 3,
}

impl fmt::Display for DisplayExpr<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_expr(self.graph, self.id, Prec::Sum, f)
    }
}

impl fmt::Debug for DisplayExpr<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// Writes a non-negative number as a factor or term.
fn write_magnitude(n: Number, f: &mut dyn Write) -> fmt::Result {
    write!(f, "{}", n.abs())
}

fn write_expr(g: &Graph, id: Id, min: Prec, f: &mut dyn Write) -> fmt::Result {
    match g.node(id) {
        Node::Num(n) => {
            if n.is_negative() && min > Prec::Sum {
                write!(f, "({n})")
            } else {
                write!(f, "{n}")
            }
        }
        Node::Sym(s) => f.write_str(g.symbol_name(*s)),
        Node::Add { constant, terms } => {
            if min > Prec::Sum {
                f.write_char('(')?;
            }
            // Print order: positive terms first, then by text (the canonical
            // order is by node id, which reads arbitrarily).
            let mut parts: Vec<(bool, String)> = terms
                .iter()
                .map(|&(b, k)| {
                    let mut t = String::new();
                    let _ = write_term(g, b, k.abs(), &mut t);
                    (k.is_negative(), t)
                })
                .collect();
            parts.sort();
            for (i, (negative, text)) in parts.iter().enumerate() {
                match (i, negative) {
                    (0, true) => f.write_char('-')?,
                    (0, false) => {}
                    (_, true) => f.write_str(" - ")?,
                    (_, false) => f.write_str(" + ")?,
                }
                f.write_str(text)?;
            }
            if !constant.is_zero() {
                f.write_str(if constant.is_negative() { " - " } else { " + " })?;
                write_magnitude(*constant, f)?;
            }
            if min > Prec::Sum {
                f.write_char(')')?;
            }
            Ok(())
        }
        Node::Mul { coeff, factors } => {
            // A leading minus binds like a sum when it is not the whole expression.
            let paren = min > Prec::Product || (coeff.is_negative() && min > Prec::Sum);
            if paren {
                f.write_char('(')?;
            }
            if coeff.is_negative() {
                f.write_char('-')?;
            }
            write_product(g, coeff.abs(), factors, f)?;
            if paren {
                f.write_char(')')?;
            }
            Ok(())
        }
        Node::Fun(Func::Hold, a) => {
            f.write_char('(')?;
            write_expr(g, *a, Prec::Sum, f)?;
            f.write_char(')')
        }
        Node::Fun(func, a) => {
            write!(f, "{}(", func.name())?;
            write_expr(g, *a, Prec::Sum, f)?;
            f.write_char(')')
        }
        Node::Atan2(y, x) | Node::Powf(y, x) => {
            let name = if matches!(g.node(id), Node::Atan2(..)) {
                "atan2("
            } else {
                "powf("
            };
            f.write_str(name)?;
            write_expr(g, *y, Prec::Sum, f)?;
            f.write_str(", ")?;
            write_expr(g, *x, Prec::Sum, f)?;
            f.write_char(')')
        }
        Node::Select(c, a, b) => {
            f.write_str("select(")?;
            write_expr(g, *c, Prec::Sum, f)?;
            f.write_str(", ")?;
            write_expr(g, *a, Prec::Sum, f)?;
            f.write_str(", ")?;
            write_expr(g, *b, Prec::Sum, f)?;
            f.write_char(')')
        }
    }
}

/// A term `k·b` with `k > 0`, as it stands inside a sum.
fn write_term(g: &Graph, b: Id, k: Number, f: &mut dyn Write) -> fmt::Result {
    if k.is_one() && !k.is_float() {
        return write_expr(g, b, Prec::Product, f);
    }
    match g.node(b) {
        Node::Mul { factors, .. } => write_product(g, k, factors, f),
        _ => write_product(g, k, &[(b, 1)], f),
    }
}

/// `k · Π b^e` with `k > 0`: numerator factors, then `/` and the denominator.
fn write_product(g: &Graph, k: Number, factors: &[(Id, i32)], f: &mut dyn Write) -> fmt::Result {
    // Print order: symbols, then functions, then parenthesized sums, each by text.
    let render = |list: Vec<(Id, i32)>| -> Vec<String> {
        let mut items: Vec<(u8, String)> = list
            .into_iter()
            .map(|(b, e)| {
                let class = match g.node(b) {
                    Node::Sym(_) => 0,
                    Node::Fun(..) | Node::Atan2(..) | Node::Powf(..) | Node::Select(..) => 1,
                    _ => 2,
                };
                let mut t = String::new();
                let _ = write_power(g, b, e, &mut t);
                (class, t)
            })
            .collect();
        items.sort();
        items.into_iter().map(|(_, t)| t).collect()
    };
    let num = render(factors.iter().copied().filter(|x| x.1 > 0).collect());
    let den = render(
        factors
            .iter()
            .copied()
            .filter(|x| x.1 < 0)
            .map(|(b, e)| (b, -e))
            .collect(),
    );
    let mut first = true;
    if !k.is_one() || k.is_float() || num.is_empty() {
        write_magnitude(k, f)?;
        first = false;
    }
    for t in &num {
        if !first {
            f.write_char('*')?;
        }
        first = false;
        f.write_str(t)?;
    }
    if !den.is_empty() {
        f.write_char('/')?;
        let group = den.len() > 1;
        if group {
            f.write_char('(')?;
        }
        f.write_str(&den.join("*"))?;
        if group {
            f.write_char(')')?;
        }
    }
    Ok(())
}

fn write_power(g: &Graph, b: Id, e: i32, f: &mut dyn Write) -> fmt::Result {
    if e == 1 {
        write_expr(g, b, Prec::Power, f)
    } else {
        write_expr(g, b, Prec::Power, f)?;
        write!(f, "^{e}")
    }
}

#[cfg(test)]
mod tests {
    use crate::Graph;

    fn show(src: &str) -> String {
        let mut g = Graph::new();
        let e = g.parse(src).unwrap();
        g.display(e).to_string()
    }

    #[test]
    fn sum_with_negative_terms() {
        assert_eq!(show("x - 2*y - 3"), "x - 2*y - 3");
    }
    #[test]
    fn quotient_groups_denominator() {
        assert_eq!(show("x/(y*z^2)"), "x/(y*z^2)");
    }
    #[test]
    fn reciprocal() {
        assert_eq!(show("-1/x"), "-1/x");
    }
    #[test]
    fn power_of_sum() {
        assert_eq!(show("(x + 1)^2"), "(x + 1)^2");
    }
    #[test]
    fn negative_product_in_function() {
        assert_eq!(show("sqrt(-x)"), "sqrt(-x)");
    }
    #[test]
    fn float_coefficient() {
        assert_eq!(show("0.5*x"), "0.5*x");
    }
    #[test]
    fn atan2_arguments() {
        assert_eq!(show("atan2(y, x + 1)"), "atan2(y, x + 1)");
    }
}
