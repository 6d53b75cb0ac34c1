//! The Python stub (`python/softarm/_core.pyi`) lists `Gains`' fields by hand, since
//! stubtest reads it; this test fails when that list and the core's one declaration
//! ([`Gains::FLOAT_FIELDS`], [`Gains::OTHER_FIELDS`]) differ.

use softarm_core::Gains;
use std::collections::BTreeSet;

/// The body of `class Gains:` in the stub.
fn gains_class(stub: &str) -> &str {
    let start = stub
        .find("\nclass Gains:")
        .expect("the stub declares Gains");
    let rest = &stub[start + 1..];
    let end = rest[1..]
        .find("\n@final")
        .or_else(|| rest[1..].find("\nclass "))
        .map_or(rest.len(), |e| e + 1);
    &rest[..end]
}

#[test]
fn the_stub_lists_exactly_the_core_gains() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../python/softarm/_core.pyi"
    );
    let stub = std::fs::read_to_string(path).expect("python/softarm/_core.pyi");
    let class = gains_class(&stub);
    let lines: Vec<&str> = class.lines().collect();
    // `@property` followed by `def name(self) -> ...`.
    let properties: BTreeSet<&str> = lines
        .windows(2)
        .filter(|w| w[0].trim() == "@property")
        .filter_map(|w| w[1].trim().strip_prefix("def "))
        .filter_map(|d| d.split('(').next())
        .collect();
    // The keywords of `__new__`: `name: type = ...,` lines up to its closing `)`.
    let new_at = lines
        .iter()
        .position(|l| l.trim_start().starts_with("def __new__("))
        .expect("Gains.__new__ in the stub");
    let keywords: BTreeSet<&str> = lines[new_at + 1..]
        .iter()
        .take_while(|l| !l.trim_start().starts_with(')'))
        .filter(|l| l.trim_end().ends_with("= ...,"))
        .filter_map(|l| l.trim().split(':').next())
        .collect();
    let core: BTreeSet<&str> = Gains::FLOAT_FIELDS
        .iter()
        .map(|f| f.name)
        .chain(Gains::OTHER_FIELDS.iter().copied())
        .collect();
    assert_eq!(properties, core, "Gains properties in the stub vs the core");
    assert_eq!(
        keywords, core,
        "Gains.__new__ keywords in the stub vs the core"
    );
}

#[test]
fn every_float_field_is_read_written_and_bounded_by_its_entry() {
    for f in Gains::FLOAT_FIELDS {
        let mut g = Gains::blackberry();
        assert!(f.accepts((f.get)(&g)), "{}", f.name);
        (f.set)(&mut g, f.max * 2.0 + 1.0);
        assert_eq!((f.get)(&g), f.max * 2.0 + 1.0);
        match g.validate() {
            Err(softarm_core::Error::Parameter { arg, .. }) => assert_eq!(arg, f.name),
            other => panic!("{}: {other:?}", f.name),
        }
        (f.set)(&mut g, f64::NAN);
        assert!(g.validate().is_err(), "{} accepts NaN", f.name);
    }
}
