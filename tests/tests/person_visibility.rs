//! Issue 4's person-visibility goal, measured with the real renderer and the real default
//! detector: in the default world, the person is labelled `person` with confidence >= 0.5 in at
//! least 90% of the frames where it is 1.5-8 m ahead and fully in view.

use rover_tests::sweep::person_sweep;

#[test]
fn the_default_person_is_recognised_wherever_it_is_fully_in_view() -> anyhow::Result<()> {
    let distances: Vec<f64> = (3..=16).map(|i| f64::from(i) * 0.5).collect();
    let sweep = person_sweep(&distances, &[-25.0, -12.0, 0.0, 12.0, 25.0], None, None)?;
    println!("{}", sweep.markdown());
    let (ok, counted) = sweep.score();
    println!("person >= 0.5 in {ok}/{counted} frames fully in view");
    // The camera sits ~0.18 m above the ground looking level, so a 1.75 m person is fully in
    // view only from about 2.6 m on; nearer frames are excluded by projection, not by hand.
    assert!(
        counted >= 40,
        "only {counted} frames had the person fully in view"
    );
    assert!(
        ok * 10 >= counted * 9,
        "person recognised in {ok}/{counted} frames, goal 90%"
    );
    Ok(())
}
