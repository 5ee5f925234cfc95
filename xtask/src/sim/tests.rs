use super::*;

#[test]
fn fault_specs_parse_and_reject_nonsense() {
    let specs = [
        "servo-silent:1@2500".to_owned(),
        "servo-silent:0@100-400".to_owned(),
        "servo-corrupt:0.05".to_owned(),
        "servo-forge:0.2".to_owned(),
        "servo-slow:3".to_owned(),
    ];
    let (faults, slow) = parse_faults(&specs).unwrap();
    assert_eq!(
        faults.silent,
        vec![
            SilentWindow {
                id: 1,
                from_ms: 2500,
                until_ms: None
            },
            SilentWindow {
                id: 0,
                from_ms: 100,
                until_ms: Some(400)
            }
        ]
    );
    assert_eq!(faults.corrupt_probability, 0.05);
    assert_eq!(faults.forge_probability, 0.2);
    assert_eq!(slow, 3.0);
    for bad in [
        "servo-silent:1",
        "servo-silent:1@500-400",
        "servo-silent:1@5-x",
        "servo-corrupt:2",
        "servo-forge:-1",
        "servo-slow:0.5",
        "gremlins:1",
        "x",
    ] {
        assert!(parse_faults(&[bad.to_owned()]).is_err(), "{bad}");
    }
}
