//! `plan --vary` reaches the `simt` model's keys: a sweep of `simt.rt_max_warps` on
//! `configs/rtx2060.toml` gives configurations that differ in that key only, and a bad
//! value is refused with the config's typed error.

use dualsplit_report::study::Vary;
use dualsplit_report::study::vary::apply;
use dualsplit_sim::SimConfig;

fn rtx2060() -> SimConfig {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/rtx2060.toml");
    SimConfig::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn simt_keys_can_be_swept() {
    let base = rtx2060();
    let v = Vary::parse("simt.rt_max_warps=1,8", &base).unwrap();
    assert_eq!(v.values.len(), 2);
    for (value, want) in v.values.iter().zip([1, 8]) {
        let cfg = apply(&base, &[(v.key.clone(), value.clone())]).unwrap();
        let s = cfg.simt.as_ref().unwrap();
        assert_eq!(s.rt_max_warps, want);
        let mut back = cfg.clone();
        back.simt.as_mut().unwrap().rt_max_warps = 4;
        assert_eq!(back, base);
    }
    assert!(Vary::parse("simt.no_such_key=1", &base).is_err());
    let zero = Vary::parse("simt.rt_max_mshr=0", &base).unwrap();
    assert!(apply(&base, &[(zero.key.clone(), zero.values[0].clone())]).is_err());
}
