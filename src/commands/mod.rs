//! One module per subcommand; `main.rs` parses the command line and hands
//! each to its module.

pub mod bench;
pub mod compare;
pub mod inspect;
pub mod run;
pub mod sweep;
pub mod validate;

/// Input that is valid but probably not meant (model::Model::warnings), on stderr.
pub(crate) fn print_warnings(m: &spatter::model::Model) {
    for w in &m.warnings {
        eprintln!("warning: {w}");
    }
}
