//! A contact scene pays for the contacts it names: its operation count is
//! that of the same robot declaring those contacts alone.

use appell_codegen::FileRoots;

/// The workspace root, which the models' URDF paths start from.
fn workspace_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// The operation counts (`total`) the expansion of `src` reports, in order:
/// the model's rhs, then each scene's.
fn rhs_totals(src: &str) -> Vec<usize> {
    let input: syn::DeriveInput = syn::parse_str(src).expect("a model");
    let roots = FileRoots::new(Some(&workspace_root()), None);
    let text = appell_codegen::expand_with(&input, &roots, &Default::default()).to_string();
    assert!(!text.contains("compile_error"), "{text}");
    text.match_indices("rhs_ops")
        .map(|(i, _)| {
            let rest = &text[i..];
            let at = rest.find("total :").expect("a total") + "total :".len();
            rest[at..]
                .split([',', '}'])
                .next()
                .and_then(|n| n.trim().parse().ok())
                .expect("a count")
        })
        .collect()
}

/// Bolt, a biped on point feet, its left foot down.
fn bolt(contacts: &str) -> String {
    format!(
        r#"#[derive(Appell)]
        #[appell(urdf("tests/robots/bolt/bolt.urdf", base = free), gravity(-9.81 * N.z))]
        #[appell({contacts})]
        #[appell(scene(left, effects(gravity, actuation, fl)))]
        struct Bolt;"#
    )
}

#[test]
fn a_contact_scene_costs_what_the_robot_with_its_contacts_alone_costs() {
    let both = rhs_totals(&bolt(
        "contact(FL_FOOT, point, effect = fl), contact(FR_FOOT, point, effect = fr)",
    ));
    let left = rhs_totals(&bolt("contact(FL_FOOT, point, effect = fl)"));
    assert_eq!(both.len(), 2, "{both:?}");
    println!("Bolt in the air and on its left foot: {both:?} operations per rhs call");
    assert_eq!(both, left);
    // And the scene pays for its foot: more than the robot in the air.
    assert!(both[1] != both[0], "{both:?}");
}

#[test]
fn a_scene_costs_the_same_after_another_scene() {
    let both = "contact(FL_FOOT, point, effect = fl), contact(FR_FOOT, point, effect = fr)";
    let alone = rhs_totals(&bolt(both));
    let src = bolt(both).replace(
        "#[appell(scene(left",
        "#[appell(scene(both, effects(gravity, actuation, fl, fr)))]\n#[appell(scene(left",
    );
    let after = rhs_totals(&src);
    assert_eq!(after.len(), 3, "{after:?}");
    assert_eq!((after[0], after[2]), (alone[0], alone[1]));
}

/// The `form` strings the expansion of `src` reports, in order: the
/// model's, then each scene's (not their Jacobians').
fn forms(src: &str) -> Vec<String> {
    let input: syn::DeriveInput = syn::parse_str(src).expect("a model");
    let roots = FileRoots::new(Some(&workspace_root()), None);
    let text = appell_codegen::expand_with(&input, &roots, &Default::default()).to_string();
    assert!(!text.contains("compile_error"), "{text}");
    text.match_indices("form : \"")
        .filter(|&(i, _)| !text[..i].trim_end().ends_with("JacobianInfo {"))
        .map(|(i, _)| {
            let rest = &text[i + "form : \"".len()..];
            rest[..rest.find('"').expect("a closing quote")].to_string()
        })
        .collect()
}

#[test]
fn a_large_trees_scene_says_its_m_and_f_come_from_the_recursions() {
    // A scene that keeps every load (here for its energies) keeps the
    // model's M and f from the recursions.
    let forms = forms(
        r#"#[derive(Appell)]
        #[appell(urdf("tests/robots/solo/solo12.urdf", base = free), gravity(-9.81 * N.z))]
        #[appell(scene(watched, effects(gravity, actuation), outputs(energies)))]
        struct Solo12;"#,
    );
    assert_eq!(forms.len(), 2, "{forms:?}");
    assert!(
        forms[0].starts_with("structured: the articulated-body algorithm"),
        "{forms:?}"
    );
    assert!(
        forms[1].starts_with("structured: M by the composite-rigid-body algorithm")
            && forms[1].contains("solved by LDLᵀ"),
        "{forms:?}"
    );
}
