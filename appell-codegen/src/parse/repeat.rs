//! Repetition and indexed names, expanded on an attribute's tokens before
//! its items are parsed.
//!
//! - `repeat(i in 1..=8, item, item, ...)` stands for its items written out
//!   once for every value of `i`, in order; repeats nest, and the bounds are
//!   integer expressions of literals and enclosing indices (`j in 0..i`).
//! - `name[index]` is the name `name_index` (`q[3]` is `q_3`, `L[i - 1]`
//!   with i = 4 is `L_3`, `c[1][2]` is `c_1_2`): an index is an integer
//!   expression of literals and repeat indices, never negative.
//! - `name[a..b]` is the list of those names (`coordinates(q[1..=8])`).
//! - inside a repeat, the index itself where a value is expected (`i * l`)
//!   is the integer literal.
//!
//! Everything after this step sees only plain names, so an indexed model
//! and the same model written out expand identically.

use proc_macro2::{Delimiter, Group, Ident, Literal, Punct, Spacing, Span, TokenStream, TokenTree};
use syn::parse::{ParseStream, Parser};
use syn::spanned::Spanned;
use syn::Token;

/// Items one model may expand to: a guard against a runaway nest of
/// repeats, far above any mechanism a compiler can digest.
const MAX_ITEMS: usize = 100_000;

/// An attribute's item list with every `repeat(...)` written out and every
/// indexed name made plain.
pub(super) fn expand(tokens: TokenStream) -> syn::Result<TokenStream> {
    let mut items = Vec::new();
    expand_items(tokens, &mut Vec::new(), &mut items)?;
    let mut out = TokenStream::new();
    for (k, item) in items.into_iter().enumerate() {
        if k > 0 {
            out.extend([TokenTree::Punct(Punct::new(',', Spacing::Alone))]);
        }
        out.extend(item);
    }
    Ok(out)
}

/// The repeat indices in scope, innermost last.
type Scope = Vec<(String, i64)>;

/// Splits `tokens` at its top-level commas and appends each item, a
/// `repeat(...)` as the items it stands for.
fn expand_items(
    tokens: TokenStream,
    scope: &mut Scope,
    out: &mut Vec<TokenStream>,
) -> syn::Result<()> {
    for item in split_commas(tokens) {
        match item.as_slice() {
            [TokenTree::Ident(id), TokenTree::Group(g)]
                if id == super::keywords::REPEAT && g.delimiter() == Delimiter::Parenthesis =>
            {
                expand_repeat(g, scope, out)?;
            }
            _ => out.push(substitute(item, scope)?),
        }
        if out.len() > MAX_ITEMS {
            return Err(syn::Error::new(
                Span::call_site(),
                format!("the repeats expand to more than {MAX_ITEMS} items"),
            ));
        }
    }
    Ok(())
}

fn split_commas(tokens: TokenStream) -> Vec<Vec<TokenTree>> {
    let mut items = vec![Vec::new()];
    for tree in tokens {
        match &tree {
            TokenTree::Punct(p) if p.as_char() == ',' => items.push(Vec::new()),
            _ => items.last_mut().expect("one item").push(tree),
        }
    }
    items.retain(|i| !i.is_empty());
    items
}

/// `repeat(i in a..b, items...)`: the items once per value of `i`.
fn expand_repeat(group: &Group, scope: &mut Scope, out: &mut Vec<TokenStream>) -> syn::Result<()> {
    let header = |s: ParseStream| -> syn::Result<(syn::Ident, syn::ExprRange, TokenStream)> {
        let index: syn::Ident = s.parse().map_err(|e| {
            syn::Error::new(
                e.span(),
                "a repeat starts with its index and range: `repeat(i in 1..=8, items...)`",
            )
        })?;
        s.parse::<Token![in]>()?;
        let range =
            match s.parse::<syn::Expr>()? {
                syn::Expr::Range(r) => r,
                other => return Err(syn::Error::new(
                    other.span(),
                    "expected a range of integers: `1..=8` or `0..n_links` written as a literal",
                )),
            };
        if !s.is_empty() {
            s.parse::<Token![,]>()?;
        }
        Ok((index, range, s.parse()?))
    };
    let (index, range, body) = header.parse2(group.stream())?;
    let name = index.to_string();
    if scope.iter().any(|(n, _)| *n == name) {
        return Err(syn::Error::new(
            index.span(),
            format!(
                "`{name}` is already the index of an enclosing repeat; give this one another name"
            ),
        ));
    }
    let values = range_values(
        &range,
        scope,
        "the bounds of a repeat",
        "a repeat's range needs both bounds: `1..=8`",
    )?;
    if values.end.saturating_sub(values.start) > MAX_ITEMS as i64 {
        return Err(syn::Error::new(
            range.span(),
            format!("a repeat of more than {MAX_ITEMS} steps"),
        ));
    }
    for value in values {
        scope.push((name.clone(), value));
        let result = expand_items(body.clone(), scope, out);
        scope.pop();
        result?;
    }
    Ok(())
}

/// One item with its indexed names made plain and the indices in scope
/// replaced by their values.
fn substitute(item: Vec<TokenTree>, scope: &Scope) -> syn::Result<TokenStream> {
    let mut out = TokenStream::new();
    let mut k = 0;
    while k < item.len() {
        let after_dot = k > 0 && matches!(&item[k - 1], TokenTree::Punct(p) if p.as_char() == '.');
        match &item[k] {
            TokenTree::Ident(id) if !after_dot && is_bracket(item.get(k + 1)) => {
                let mut names = vec![id.to_string()];
                k += 1;
                while let Some(TokenTree::Group(g)) = item.get(k).filter(|t| is_bracket(Some(t))) {
                    let indices = index_values(g, scope)?;
                    names = names
                        .iter()
                        .flat_map(|n| indices.iter().map(move |i| format!("{n}_{i}")))
                        .collect();
                    k += 1;
                }
                for (j, name) in names.iter().enumerate() {
                    if j > 0 {
                        out.extend([TokenTree::Punct(Punct::new(',', Spacing::Alone))]);
                    }
                    out.extend([TokenTree::Ident(Ident::new(name, id.span()))]);
                }
                continue;
            }
            TokenTree::Ident(id) if !after_dot && !is_key(item.get(k + 1), item.get(k + 2)) => {
                match scope.iter().rev().find(|(n, _)| id == n) {
                    Some((_, value)) => out.extend(literal(*value, id.span())),
                    None => out.extend([item[k].clone()]),
                }
            }
            TokenTree::Group(g) => {
                let inner = substitute(g.stream().into_iter().collect(), scope)?;
                let mut copy = Group::new(g.delimiter(), inner);
                copy.set_span(g.span());
                out.extend([TokenTree::Group(copy)]);
            }
            other => out.extend([other.clone()]),
        }
        k += 1;
    }
    Ok(out)
}

fn is_bracket(tree: Option<&TokenTree>) -> bool {
    matches!(tree, Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Bracket)
}

/// Whether a name is followed by a lone `=` (a key such as `mass = m`, or
/// a definition such as `point(P = ...)`), not `==`.
fn is_key(next: Option<&TokenTree>, after: Option<&TokenTree>) -> bool {
    let eq = |t: Option<&TokenTree>| matches!(t, Some(TokenTree::Punct(p)) if p.as_char() == '=');
    eq(next) && !eq(after)
}

/// An integer literal, in parentheses when negative.
fn literal(value: i64, span: Span) -> TokenStream {
    let mut lit = Literal::i64_unsuffixed(value.abs());
    lit.set_span(span);
    if value >= 0 {
        return TokenStream::from(TokenTree::Literal(lit));
    }
    let mut minus = Punct::new('-', Spacing::Alone);
    minus.set_span(span);
    let inner: TokenStream = [TokenTree::Punct(minus), TokenTree::Literal(lit)]
        .into_iter()
        .collect();
    let mut group = Group::new(Delimiter::Parenthesis, inner);
    group.set_span(span);
    TokenStream::from(TokenTree::Group(group))
}

/// The values of `[index]`, a non-negative integer, or of `[a..b]`, a
/// range of them (`q[1..=3]` is `q_1, q_2, q_3`, for lists).
fn index_values(group: &Group, scope: &Scope) -> syn::Result<Vec<i64>> {
    let e: syn::Expr = syn::parse2(group.stream()).map_err(|_| {
        syn::Error::new(group.span(), "an index is an integer expression: `q[3]`, `L[i - 1]`, or a range in a list: `q[1..=8]`")
    })?;
    let values = match &e {
        syn::Expr::Range(r) => range_values(
            r,
            scope,
            "an index range",
            "an index range needs both bounds: `q[1..=8]`",
        )?
        .collect(),
        e => vec![evaluate(e, scope, "an index")?],
    };
    if let Some(v) = values.iter().find(|v| **v < 0) {
        return Err(syn::Error::new(
            group.span(),
            format!(
                "this index is {v} here{}; indices start at 0: start the repeat later, or declare the first element before it",
                describe(scope)
            ),
        ));
    }
    Ok(values)
}

/// The integers of `a..b` or `a..=b`, its bounds evaluated as `what`;
/// `open` is the error for a missing bound.
fn range_values(
    range: &syn::ExprRange,
    scope: &Scope,
    what: &str,
    open: &str,
) -> syn::Result<std::ops::Range<i64>> {
    let bound = |b: &Option<Box<syn::Expr>>| match b {
        Some(b) => evaluate(b, scope, what),
        None => Err(syn::Error::new(range.span(), open)),
    };
    let (start, end) = (bound(&range.start)?, bound(&range.end)?);
    Ok(match range.limits {
        syn::RangeLimits::HalfOpen(_) => start..end,
        syn::RangeLimits::Closed(_) => start..end + 1,
    })
}

/// ` (i = 0, j = 2)`: the indices in scope, for errors.
fn describe(scope: &Scope) -> String {
    if scope.is_empty() {
        return String::new();
    }
    let values: Vec<String> = scope.iter().map(|(n, v)| format!("{n} = {v}")).collect();
    format!(" ({})", values.join(", "))
}

/// An integer expression of literals and repeat indices; `what` names its
/// role in the error.
fn evaluate(e: &syn::Expr, scope: &Scope, what: &str) -> syn::Result<i64> {
    let overflow = || syn::Error::new(e.span(), format!("{what} overflows"));
    Ok(match e {
        syn::Expr::Lit(syn::ExprLit { lit: syn::Lit::Int(i), .. }) => i.base10_parse()?,
        syn::Expr::Paren(p) => evaluate(&p.expr, scope, what)?,
        syn::Expr::Group(g) => evaluate(&g.expr, scope, what)?,
        syn::Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => -evaluate(&u.expr, scope, what)?,
        syn::Expr::Path(p) if p.path.get_ident().is_some() => {
            let id = p.path.get_ident().expect("checked");
            match scope.iter().rev().find(|(n, _)| id == n) {
                Some((_, v)) => *v,
                None => {
                    return Err(syn::Error::new(
                        id.span(),
                        format!(
                            "{what} must be integer literals or indices of enclosing repeats, and `{id}` is neither: the repetition happens at compile time, so write the number itself"
                        ),
                    ))
                }
            }
        }
        syn::Expr::Binary(b) => {
            let (l, r) = (evaluate(&b.left, scope, what)?, evaluate(&b.right, scope, what)?);
            match b.op {
                syn::BinOp::Add(_) => l.checked_add(r).ok_or_else(overflow)?,
                syn::BinOp::Sub(_) => l.checked_sub(r).ok_or_else(overflow)?,
                syn::BinOp::Mul(_) => l.checked_mul(r).ok_or_else(overflow)?,
                syn::BinOp::Div(_) | syn::BinOp::Rem(_) if r == 0 => {
                    return Err(syn::Error::new(b.right.span(), format!("{what}: division by zero")))
                }
                syn::BinOp::Div(_) => l.div_euclid(r),
                syn::BinOp::Rem(_) => l.rem_euclid(r),
                _ => {
                    return Err(syn::Error::new(
                        b.op.span(),
                        format!("{what} may use only `+ - * / %`"),
                    ))
                }
            }
        }
        other => {
            return Err(syn::Error::new(
                other.span(),
                format!("{what} must be integer literals or indices of enclosing repeats, combined with `+ - * / %`"),
            ))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use quote::quote;

    fn expanded(tokens: TokenStream) -> String {
        expand(tokens).unwrap().to_string()
    }

    fn error(tokens: TokenStream) -> String {
        expand(tokens).unwrap_err().to_string()
    }

    #[test]
    fn repeat_writes_the_items_out_in_order() {
        let out = expanded(quote!(
            coordinates(q[0]),
            repeat(i in 1..=2, frame(L[i] = L[i - 1].rotate_z(q[i])), particle(P[i], mass = m[i])),
            gravity(-g * N.y)
        ));
        assert_eq!(
            out,
            quote!(
                coordinates(q_0),
                frame(L_1 = L_0.rotate_z(q_1)),
                particle(P_1, mass = m_1),
                frame(L_2 = L_1.rotate_z(q_2)),
                particle(P_2, mass = m_2),
                gravity(-g * N.y)
            )
            .to_string()
        );
    }

    #[test]
    fn nested_repeats_see_the_enclosing_index() {
        let out = expanded(quote!(repeat(i in 0..3, repeat(j in 0..i, c(a[i][j] = i * j)))));
        assert_eq!(
            out,
            quote!(c(a_1_0 = 1 * 0), c(a_2_0 = 2 * 0), c(a_2_1 = 2 * 1)).to_string()
        );
    }

    #[test]
    fn an_index_in_a_value_is_its_literal_but_not_after_a_dot_or_as_a_key() {
        // `x` is the index: `N.x` keeps its axis, `x = ...` its key.
        let out =
            expanded(quote!(repeat(x in 2..3, point(P[x] = O + x * l * N.x), body(b, x = x))));
        assert_eq!(
            out,
            quote!(point(P_2 = O + 2 * l * N.x), body(b, x = 2)).to_string()
        );
        let out = expanded(quote!(repeat(i in -1..0, point(P = O + i * N.x))));
        assert_eq!(out, quote!(point(P = O + (-1) * N.x)).to_string());
    }

    #[test]
    fn an_index_range_is_a_list_of_names() {
        let out = expanded(quote!(coordinates(x, q[1..=3]), speeds(q[0..2][1])));
        assert_eq!(
            out,
            quote!(coordinates(x, q_1, q_2, q_3), speeds(q_0_1, q_1_1)).to_string()
        );
    }

    #[test]
    fn an_empty_range_and_trailing_commas_leave_no_empty_item() {
        let out = expanded(quote!(a(), repeat(i in 0..0, b(i)), c(),));
        assert_eq!(out, quote!(a(), c()).to_string());
    }

    #[test]
    fn bounds_and_indices_must_be_known_at_compile_time() {
        let e = error(quote!(repeat(i in 0..n, particle(P[i], mass = m))));
        assert!(
            e.contains("the bounds of a repeat must be integer literals"),
            "{e}"
        );
        assert!(e.contains("`n` is neither"), "{e}");
        let e = error(quote!(point(P[k] = O)));
        assert!(e.contains("an index must be integer literals"), "{e}");
        let e = error(quote!(repeat(i in 0..2, point(P[i - 1] = O))));
        assert!(e.contains("this index is -1"), "{e}");
        let e = error(quote!(repeat(i in 0.., point(P[i] = O))));
        assert!(e.contains("needs both bounds"), "{e}");
        let e = error(quote!(repeat(i in 0..2, repeat(i in 0..2, a()))));
        assert!(e.contains("already the index"), "{e}");
        let e = error(quote!(repeat(i in 0..3, a(q[i / (i - i)]))));
        assert!(e.contains("division by zero"), "{e}");
    }
}
