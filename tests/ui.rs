//! Compile-fail cases: each bad model must be rejected with an error whose
//! span points at the culprit (`tests/ui/<category>/<case>.stderr`).

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*/*.rs");
}
