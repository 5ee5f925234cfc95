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

#[derive(clap::Parser)]
struct Cli {
    #[command(flatten)]
    args: SimArgs,
}

#[test]
fn the_spot_feed_is_the_named_file_and_needs_one_without_a_pty_link() {
    use clap::Parser as _;
    let parse = |extra: &[&str]| {
        let argv = ["sim", "--interactive"].iter().chain(extra).copied();
        Cli::try_parse_from(argv).unwrap().args
    };
    let named = prepare(&parse(&["--spot-feed", "/tmp/feed"])).unwrap();
    assert_eq!(named.options.spot_feed, Some(PathBuf::from("/tmp/feed")));
    assert_eq!(prepare(&parse(&[])).unwrap().options.spot_feed, None);
    let e = prepare(&parse(&["--spot-feed"])).err().unwrap().to_string();
    assert!(e.contains("--spot-feed needs a FILE"), "{e}");
    assert_eq!(
        laser_sim::spot_feed::beside(Path::new("/tmp/laser")),
        PathBuf::from("/tmp/laser.spot")
    );
}
