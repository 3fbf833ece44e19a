//! The token form of a written program ([`Program::to_tokens`]): small
//! programs against their expected tokens, and larger ones checked
//! structurally against the text form (same tokens in the same order, no
//! parsing involved).

use proc_macro2::{Delimiter, TokenStream, TokenTree};

use super::{ConstantForm, EmitOptions, Program, RustPath, ScalarType};
use crate::graph::{Graph, SymbolKind};
use crate::workloads::spatial_chain;

/// The options of generic code over `__T` (fused products) and of plain
/// `f64` code, besides the defaults.
fn variants() -> Vec<EmitOptions> {
    let d = EmitOptions::default();
    vec![
        d.clone(),
        EmitOptions {
            fused: true,
            ..d.clone()
        },
        EmitOptions {
            cse: false,
            hoist_parameters: false,
            ..d.clone()
        },
        EmitOptions {
            scalar: ScalarType::named("__T"),
            constant: ConstantForm::FromF64 {
                scalar_trait: RustPath::absolute(&["appell", "__private", "Scalar"]),
            },
            fused: true,
            ..d.clone()
        },
        EmitOptions {
            scalar: ScalarType::named("f64"),
            constant: ConstantForm::F64Literal,
            hoist_parameters: false,
            ..d
        },
    ]
}

fn strings(v: &[TokenStream]) -> Vec<String> {
    v.iter().map(|t| t.to_string()).collect()
}

#[test]
fn a_small_program_as_tokens() {
    let mut g = Graph::new();
    g.parameter("m").unwrap();
    g.parameter("l").unwrap();
    let e = g.parse("m*l^2*sin(q)*cos(q) + m*l^2*q").unwrap();
    let p = Program::lower(&g, &[e]);
    let t = p.to_tokens(&g, &EmitOptions::default());
    assert_eq!(strings(&t.prepare), ["let p0 = l * l * m ;"]);
    assert_eq!(t.hoisted[0].to_string(), "p0");
    assert!(t.body.is_empty());
    assert_eq!(
        strings(&t.outputs),
        ["q . sin () * p0 * q . cos () + q * p0"]
    );
}

#[test]
fn constants_parentheses_and_negative_literals() {
    let mut g = Graph::new();
    let e = g.parse("(x - y)/2 - 0.25*z - (x + y)*(x - y)").unwrap();
    let f = g.parse("atan2(x, y) - 3/4").unwrap();
    let h = g.parse("sin(x) * (-2.5) * y + cos(x)/(x-y)").unwrap();
    let p = Program::lower(&g, &[e, f, h]);
    let t = p.to_tokens(&g, &EmitOptions::default());
    let from_f64 = |lit: &str| format!("< T as :: appell_core :: Scalar > :: from_f64 ({lit})");
    assert_eq!(
        strings(&t.body),
        [
            format!("let k1_2 : T = {} ;", from_f64("0.5")),
            format!("let km1_2 : T = {} ;", from_f64("- 0.5")),
            format!("let kf : T = {} ;", from_f64("0.25")),
            format!("let k3_4 : T = {} ;", from_f64("0.75")),
            format!("let kf_2 : T = {} ;", from_f64("2.5")),
            "let t0 = x - y ;".to_string(),
        ]
    );
    assert_eq!(
        strings(&t.outputs),
        [
            "x * (k1_2 - t0) - z * kf + y * (km1_2 - t0)",
            "x . atan2 (y) - k3_4",
            "x . cos () / t0 - y * kf_2 * x . sin ()",
        ]
    );
}

#[test]
fn fused_products_and_powers() {
    let mut g = Graph::new();
    let e = g.parse("x*y - z + atan2(y, x)*w - x^70 * z^-80").unwrap();
    let p = Program::lower(&g, &[e]);
    let o = EmitOptions {
        fused: true,
        ..EmitOptions::default()
    };
    let c = p.to_rust(&g, &o);
    let t = p.to_tokens(&g, &o);
    assert_eq!(
        c.outputs,
        ["y.atan2(x).fma(w, x.fma(y - x.powi(69) / z.powi(80), -z))"]
    );
    assert_eq!(
        strings(&t.outputs),
        ["y . atan2 (x) . fma (w , \
             x . fma (y - x . powi (69) / z . powi (80) , - z))"]
    );
}

/// Float literals in tokens are built from the value: the shortest decimal
/// that reads back as it, without exponent, and `f64` as suffix.
#[test]
fn float_literals_are_built_from_their_value() {
    let mut g = Graph::new();
    let e = g.parse("x*1e-20 - y*2.5 + z*1e20").unwrap();
    let p = Program::lower(&g, &[e]);
    let variants = variants();
    let (generic, concrete) = (&variants[0], &variants[4]);
    let c = p.to_rust(&g, generic);
    let t = p.to_tokens(&g, generic);
    let from_f64 = |lit: &str| format!("< T as :: appell_core :: Scalar > :: from_f64 ({lit})");
    assert_eq!(
        c.body,
        [
            "let kf: T = <T as ::appell_core::Scalar>::from_f64(1e-20);",
            "let kf_2: T = <T as ::appell_core::Scalar>::from_f64(2.5);",
            "let kf_3: T = <T as ::appell_core::Scalar>::from_f64(1e20);",
        ]
    );
    assert_eq!(
        strings(&t.body),
        [
            format!("let kf : T = {} ;", from_f64("0.00000000000000000001")),
            format!("let kf_2 : T = {} ;", from_f64("2.5")),
            format!("let kf_3 : T = {} ;", from_f64("100000000000000000000.0")),
        ]
    );
    let c = p.to_rust(&g, concrete);
    let t = p.to_tokens(&g, concrete);
    assert_eq!(
        c.body,
        [
            "let kf: f64 = 1e-20_f64;",
            "let kf_2: f64 = 2.5_f64;",
            "let kf_3: f64 = 1e20_f64;",
        ]
    );
    assert_eq!(
        strings(&t.body),
        [
            "let kf : f64 = 0.00000000000000000001f64 ;",
            "let kf_2 : f64 = 2.5f64 ;",
            "let kf_3 : f64 = 100000000000000000000f64 ;",
        ]
    );
}

/// Whether `s` is one identifier.
fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c == '_' || c.is_ascii_alphabetic())
        && chars.all(|c| c == '_' || c.is_ascii_alphanumeric())
}

/// The text of `tokens` without whitespace, each identifier checked, each
/// float literal spelled by `float` (to compare with the text form, which
/// writes float literals in `Debug` notation).
fn squeezed(tokens: TokenStream, out: &mut String) {
    for tt in tokens {
        match tt {
            TokenTree::Ident(i) => {
                let s = i.to_string();
                assert!(is_identifier(&s), "identifier `{s}`");
                out.push_str(&s);
            }
            TokenTree::Punct(p) => out.push(p.as_char()),
            TokenTree::Literal(l) => out.push_str(&l.to_string()),
            TokenTree::Group(gr) => {
                assert_eq!(gr.delimiter(), Delimiter::Parenthesis);
                out.push('(');
                squeezed(gr.stream(), out);
                out.push(')');
            }
        }
    }
}

/// `text` with its `_f64` literals spelled as `proc_macro2` builds them:
/// `2.0_f64` as `2f64`, `0.5_f64` as `0.5f64` (the magnitudes of the
/// programs compared have no exponent).
fn f64_literals_as_built(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(k) = rest.find("_f64") {
        let (head, tail) = rest.split_at(k);
        if head.ends_with(|c: char| c.is_ascii_digit()) {
            out.push_str(head.strip_suffix(".0").unwrap_or(head));
            out.push_str("f64");
        } else {
            out.push_str(head);
            out.push_str("_f64");
        }
        rest = &tail[4..];
    }
    out.push_str(rest);
    out
}

fn without_spaces(s: &str) -> String {
    s.chars().filter(|c| !c.is_whitespace()).collect()
}

/// Every statement and output of the chain kinematics, under every variant
/// of the options, reads as the text form token by token (up to the
/// literal spelling of [`ConstantForm::F64Literal`]): a `let` of a valid
/// identifier ending in `;`, and non-empty expressions.
#[test]
fn tokens_follow_the_text_form_for_whole_programs() {
    for n in 1..=3 {
        let mut g = Graph::new();
        let chain = spatial_chain(&mut g, n).unwrap();
        for i in 1..=n {
            g.declare(&format!("l{i}"), SymbolKind::Parameter).unwrap();
        }
        let extra = g.parse("l1^2/3 - 0.5*q1 + sin(q1)^71").unwrap();
        let mut roots = chain.acceleration_roots();
        roots.push(extra);
        let p = Program::lower(&g, &roots);
        for o in variants() {
            let c = p.to_rust(&g, &o);
            let t = p.to_tokens(&g, &o);
            let same = |text: &str, tokens: &TokenStream| {
                assert!(!tokens.is_empty());
                let mut s = String::new();
                squeezed(tokens.clone(), &mut s);
                let expected = f64_literals_as_built(&without_spaces(text));
                assert_eq!(s, expected);
            };
            let stmt = |text: &str, tokens: &TokenStream| {
                same(text, tokens);
                let all: Vec<TokenTree> = tokens.clone().into_iter().collect();
                assert!(matches!(&all[0], TokenTree::Ident(i) if i == "let"));
                assert!(matches!(all.last(), Some(TokenTree::Punct(p)) if p.as_char() == ';'));
            };
            assert_eq!(c.prepare.len(), t.prepare.len());
            assert_eq!(c.body.len(), t.body.len());
            assert_eq!(c.outputs.len(), t.outputs.len());
            assert_eq!(c.stages.len(), t.stages.len());
            for (a, b) in c.prepare.iter().zip(&t.prepare) {
                stmt(a, b);
            }
            for (a, b) in c.body.iter().zip(&t.body) {
                stmt(a, b);
            }
            for (sa, sb) in c.stages.iter().zip(&t.stages) {
                assert_eq!(sa.len(), sb.len());
                for (a, b) in sa.iter().zip(sb) {
                    stmt(a, b);
                }
            }
            for (a, b) in c.outputs.iter().zip(&t.outputs) {
                same(a, b);
            }
            let names: Vec<String> = t.hoisted.iter().map(|h| h.to_string()).collect();
            assert_eq!(names, c.hoisted);
            assert_eq!((c.ops, c.prepare_ops), (t.ops, t.prepare_ops));
        }
    }
}

#[test]
#[should_panic(expected = "not a Rust identifier")]
fn a_symbol_read_by_a_non_identifier_cannot_be_tokens() {
    let mut g = Graph::new();
    let e = g.parse("x + 1").unwrap();
    let x = g.declare("x", SymbolKind::Auxiliary).unwrap();
    let p = Program::lower(&g, &[e]);
    let mut o = EmitOptions::default();
    o.symbol_text.insert(x, "self.x".to_string());
    assert_eq!(p.to_rust(&g, &o).outputs, ["self.x + k1"]);
    p.to_tokens(&g, &o);
}
