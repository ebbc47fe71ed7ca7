//! Shadow-map updates by priority: the brightest first, none starves, current maps are left.

use gibench_barczak::schedule::ShadowMapSchedule;
use glam::Vec3;

#[test]
fn brightest_first_and_current_maps_left_alone() {
    // Lights 0..10 of rising brightness; only the even ones go out of date.
    let mut s = ShadowMapSchedule::new((0..10).map(|i| Vec3::new(0.1, i as f32, 0.2)));
    s.mark(&[0, 2, 4, 6, 8]);
    assert_eq!(s.stale(), 5);
    assert_eq!(s.next_frame(2), vec![6, 8]);
    // Next frame 0, 2 and 4 are two frames out of date: 4's priority is 4 × 2 = 8, below a
    // newly marked 9's 9 × 1.
    s.mark(&[9]);
    assert_eq!(s.next_frame(1), vec![9]);
    // Now 4 has age 3 (12) vs 2 (6) vs 0 (0.2 × 3).
    assert_eq!(s.next_frame(1), vec![4]);
    assert_eq!(s.next_frame(5), vec![0, 2]);
    assert_eq!(s.next_frame(5), Vec::<u32>::new());
}

/// 300 lights whose brightness spans 1 to 100, every map made out of date every frame (a mover
/// in view of all), 100 updates a frame: every map is re-rendered, none waits longer than its
/// dimness allows (brightest / own brightness × 300 / 100 frames, plus one), and the brightest
/// wait least.
#[test]
fn no_map_starves() {
    let flux: Vec<Vec3> = (0..300)
        .map(|i| Vec3::splat(1.0 + 99.0 * ((i * 37) % 300) as f32 / 299.0))
        .collect();
    let mut s = ShadowMapSchedule::new(flux.iter().copied());
    let all: Vec<u32> = (0..300).collect();
    let mut last = vec![0u32; 300];
    let mut worst = vec![0u32; 300];
    for frame in 1..=200u32 {
        s.mark(&all);
        for l in s.next_frame(100) {
            worst[l as usize] = worst[l as usize].max(frame - last[l as usize]);
            last[l as usize] = frame;
        }
    }
    for l in 0..300 {
        worst[l] = worst[l].max(200 - last[l]);
    }
    let top = flux.iter().map(|f| f.x).fold(0f32, f32::max);
    for l in 0..300 {
        assert!(last[l] > 0, "map {l} was never re-rendered");
        let bound = (top / flux[l].x * 3.0).ceil() as u32 + 1;
        assert!(
            worst[l] <= bound,
            "map {l} (brightness {}) waited {} frames > {bound}",
            flux[l].x,
            worst[l]
        );
    }
    eprintln!("longest wait {} frames", worst.iter().max().unwrap());
    let brightest = (0..300)
        .max_by(|&a, &b| flux[a].x.total_cmp(&flux[b].x))
        .unwrap();
    let dimmest = (0..300)
        .min_by(|&a, &b| flux[a].x.total_cmp(&flux[b].x))
        .unwrap();
    assert!(
        worst[brightest] < worst[dimmest],
        "{} vs {}",
        worst[brightest],
        worst[dimmest]
    );
}
