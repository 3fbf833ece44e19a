//! The `ModelInfo` a generated model describes itself with: names of its
//! parameters, coordinates, speeds and inputs, how the derivation sorted
//! the coordinates, where each constraint row comes from, the rolling
//! contacts and bodies, the rhs's operation count and the equations text.

use appell_symbolic::OpCount;
use proc_macro2::TokenStream;
use quote::quote;

use super::{int, p, Emitter};
use crate::derivation::{Elimination, RowSource};

impl Emitter<'_> {
    /// The `ModelInfo` value; `extra_ops` are the rhs's operations outside
    /// the engine's program (the numeric solves and the LDLᵀ).
    pub(super) fn info(
        &self,
        rhs_ops: OpCount,
        extra_ops: usize,
        form: &str,
        jacobian: &super::jacobian::JacobianParts,
    ) -> TokenStream {
        let p = p();
        let d = self.d;
        let model = self.model;
        let names = |idx: &[usize]| {
            let names = idx.iter().map(|&i| self.coord(i).to_string());
            quote!(&[#(#names),*])
        };
        let strings = |v: Vec<String>| quote!(&[#(#v),*]);
        let bodies = model.bodies.iter().map(|b| {
            let (name, rigid) = (&b.name, b.frame.is_some());
            quote!(#p::BodyInfo { name: #name, rigid: #rigid })
        });
        let row_sources = self.row_sources();
        let contacts = self.d.constraint_set.rolling.iter().map(|r| {
            let (body, point, along) = (int(r.body), &r.point, r.along.is_some());
            quote!(#p::ContactInfo { body: #body, point: #point, along: #along })
        });
        let name = self.info_name();
        let params = strings(model.params.iter().map(|p| p.ident.to_string()).collect());
        let all = names(&(0..d.n).collect::<Vec<_>>());
        let speeds = strings(self.speeds().iter().map(|sp| sp.name.clone()).collect());
        let dependent = names(&d.speeds.dependent);
        let cyclic = names(&d.reduction.cyclic);
        let ignorable = names(&d.reduction.ignorable);
        let retained = names(&d.reduction.retained);
        let inputs = strings(self.inputs().iter().map(|(i, _)| i.to_string()).collect());
        let effects = strings(self.effects());
        let outputs = strings(self.outputs());
        let holonomic = int(d.constraints.holonomic.len());
        let m = int(d.m);
        let (nf, nt) = (int(self.forces().len()), int(self.torques().len()));
        let symbolic = matches!(d.elimination, Elimination::Symbolic);
        let (add, mul, div, calls) = (
            int(rhs_ops.add),
            int(rhs_ops.mul),
            int(rhs_ops.div),
            int(rhs_ops.calls),
        );
        let total = int(rhs_ops.total() + extra_ops);
        let text = format!("rhs: {form}\njacobian: {}\n\n{}", jacobian.summary, d.text);
        let jacobian = jacobian.info(appell_core::OpCounts {
            add: rhs_ops.add,
            mul: rhs_ops.mul,
            div: rhs_ops.div,
            calls: rhs_ops.calls,
            total: rhs_ops.total() + extra_ops,
        });
        quote! {
            #p::ModelInfo {
                name: #name,
                parameters: #params,
                coordinates: #all,
                speeds: #speeds,
                dependent: #dependent,
                cyclic: #cyclic,
                ignorable: #ignorable,
                retained: #retained,
                inputs: #inputs,
                effects: #effects,
                outputs: #outputs,
                holonomic: #holonomic,
                constraints: #m,
                row_sources: &[#(#row_sources),*],
                contacts: &[#(#contacts),*],
                bodies: &[#(#bodies),*],
                force_points: #nf,
                torques: #nt,
                form: #form,
                symbolic_elimination: #symbolic,
                rhs_ops: #p::OpCounts { add: #add, mul: #mul, div: #div, calls: #calls, total: #total },
                jacobian: #jacobian,
                equations: #text,
            }
        }
    }

    /// Where each constraint row comes from, a row whose residual reads a
    /// commanded rate as `Driven`.
    fn row_sources(&self) -> Vec<TokenStream> {
        let p = p();
        let (d, model) = (self.d, self.model);
        let driven = |e: appell_symbolic::Id| {
            model
                .input_rates
                .iter()
                .any(|(s, _)| model.g.depends_on(e, *s))
        };
        // `nonholonomic: dt(psi1) == w_cmd`, the tokens as written.
        let label = |kind: &str, at: &proc_macro2::TokenStream| {
            let mut text = at.to_string();
            for (from, to) in [(" (", "("), ("( ", "("), (" )", ")"), (" ,", ",")] {
                text = text.replace(from, to);
            }
            format!("{kind}: {text}")
        };
        d.constraints
            .sources
            .iter()
            .zip(&d.constraints.at)
            .map(|(r, at)| match *r {
                RowSource::Holonomic { index }
                    if driven(self.d.constraint_set.holonomic[index].residual) =>
                {
                    let (i, c) = (int(index), label("holonomic", at));
                    quote!(#p::RowSource::Driven { holonomic: true, index: #i, constraint: #c })
                }
                RowSource::Nonholonomic { index }
                    if driven(self.d.constraint_set.nonholonomic[index].residual) =>
                {
                    let (i, c) = (int(index), label("nonholonomic", at));
                    quote!(#p::RowSource::Driven { holonomic: false, index: #i, constraint: #c })
                }
                RowSource::Holonomic { index } => {
                    let i = int(index);
                    quote!(#p::RowSource::Holonomic { index: #i })
                }
                RowSource::Nonholonomic { index } => {
                    let i = int(index);
                    quote!(#p::RowSource::Nonholonomic { index: #i })
                }
                RowSource::Rolling { contact, direction } => {
                    let (c, k) = (int(contact), int(direction));
                    quote!(#p::RowSource::Rolling { contact: #c, direction: #k })
                }
                RowSource::Contact { contact, axis } => {
                    let (c, k) = (int(contact), int(axis));
                    quote!(#p::RowSource::Contact { contact: #c, axis: #k })
                }
                RowSource::Driven { .. } => unreachable!("the derivation labels no row driven"),
            })
            .collect()
    }
}
