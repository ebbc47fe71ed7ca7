//! Fuzzing on stable Rust: structure-aware generators (proptest) for every input gibench parses
//! from files users and fleets hand it — the scene descriptor, glTF binaries, results files,
//! `reproduce all` manifests, run/sweep shard records — and for the command line's value
//! parsers. Each target mutates valid inputs (JSON values replaced, removed, duplicated or
//! given hostile numbers and strings; bytes flipped, cut or inserted) and requires of every
//! input: no panic, a time per input under [`TIME_BOUND`] and no allocation beyond
//! [`ALLOC_BOUND`] over the input's own size (counted per thread by this binary's allocator).
//!
//! In the test suite each target runs `GIBENCH_FUZZ_CASES` inputs (default 256); a campaign
//! is the same command with a larger count (docs/output.md, "Fuzzing"):
//!
//! ```sh
//! GIBENCH_FUZZ_CASES=200000 cargo test --release --test fuzz -- --nocapture
//! ```
//!
//! An input that fails is written to `target/fuzz-failures/TARGET-*.bin`; once fixed it is
//! committed to `tests/fuzz-corpus/TARGET/` and every run replays that folder.
//!
//! A binary of its own, apart from `it`, because it needs its own process: it installs its own
//! global allocator to count allocations.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use serde_json::Value;

/// Bytes a target may allocate at its peak for one input, beyond the input's own size.
const ALLOC_BOUND: isize = 64 << 20;
/// Time one input may take (far above any parser's; a hang or a quadratic blow-up passes it).
const TIME_BOUND: Duration = Duration::from_secs(5);

// ---- Allocation counting (this thread's live bytes and their peak) ----

struct Counting;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn count(delta: isize) {
    let _ = LIVE.try_with(|l| {
        let v = l.get() + delta;
        l.set(v);
        let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
    });
}

// SAFETY: every call is passed on to the system allocator unchanged; only counted.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            count(l.size() as isize);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(l) };
        if !p.is_null() {
            count(l.size() as isize);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        count(-(l.size() as isize));
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            count(new as isize - l.size() as isize);
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// `f`'s result and the most bytes this thread held during it beyond what it held before.
fn peak_during<R>(f: impl FnOnce() -> R) -> (R, isize) {
    let start = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(start));
    let r = f();
    (r, PEAK.with(Cell::get) - start)
}

// ---- Mutations ----

/// A hostile JSON value: extreme and odd numbers, strings that are paths, huge or empty, and
/// small containers.
fn hostile_value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        prop_oneof![
            Just(0i64),
            Just(-1),
            Just(1),
            Just(i64::MIN),
            Just(i64::MAX),
            Just(u32::MAX as i64),
            Just(1 << 31),
            any::<i64>()
        ]
        .prop_map(Value::from),
        prop_oneof![
            Just(1e308),
            Just(-1e308),
            Just(1e-308),
            Just(1e33),
            Just(0.5),
            Just(-0.0),
            any::<f64>().prop_filter("finite", |f| f.is_finite())
        ]
        .prop_map(Value::from),
        prop_oneof![
            Just(String::new()),
            Just("../../etc/passwd".to_string()),
            Just("/dev/zero".to_string()),
            Just("x".repeat(10_000)),
            "[a-z0-9=x,./_-]{0,12}",
            any::<String>()
        ]
        .prop_map(Value::from),
    ];
    leaf.prop_recursive(2, 8, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::from),
            prop::collection::btree_map("[a-z_]{1,8}", inner, 0..3)
                .prop_map(|m| Value::Object(m.into_iter().collect())),
        ]
    })
}

/// One change to a JSON document: at the node picked by `at` (an index into its nodes in
/// order, modulo their count), replace its value, remove it, duplicate it into its array, or
/// add a key (unknown to the schema) beside it.
#[derive(Debug, Clone)]
enum Edit {
    Replace(u32, Value),
    Remove(u32),
    Duplicate(u32),
    AddKey(u32, String, Value),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<u32>(), hostile_value()).prop_map(|(a, v)| Edit::Replace(a, v)),
        1 => any::<u32>().prop_map(Edit::Remove),
        1 => any::<u32>().prop_map(Edit::Duplicate),
        1 => (any::<u32>(), "[a-z_]{1,10}", hostile_value()).prop_map(|(a, k, v)| Edit::AddKey(a, k, v)),
    ]
}

/// A byte-level change to the serialised text: flip a byte, cut the text, or insert bytes.
#[derive(Debug, Clone)]
enum ByteEdit {
    Flip(u32, u8),
    Truncate(u32),
    Insert(u32, Vec<u8>),
}

fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    prop_oneof![
        (any::<u32>(), any::<u8>()).prop_map(|(a, b)| ByteEdit::Flip(a, b)),
        any::<u32>().prop_map(ByteEdit::Truncate),
        (any::<u32>(), prop::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(a, b)| ByteEdit::Insert(a, b)),
    ]
}

/// Edits to a JSON document, then (sometimes) to its bytes.
#[derive(Debug, Clone)]
struct Mutation {
    seed: usize,
    edits: Vec<Edit>,
    bytes: Vec<ByteEdit>,
}

fn mutation(seeds: usize) -> impl Strategy<Value = Mutation> {
    (
        0..seeds.max(1),
        prop::collection::vec(edit(), 1..4),
        prop_oneof![
            4 => Just(Vec::new()),
            1 => prop::collection::vec(byte_edit(), 1..3),
        ],
    )
        .prop_map(|(seed, edits, bytes)| Mutation { seed, edits, bytes })
}

/// The node at position `at` (modulo the count) of `v` in depth-first order.
fn node_mut(v: &mut Value, at: u32) -> &mut Value {
    fn count(v: &Value) -> usize {
        1 + match v {
            Value::Array(a) => a.iter().map(count).sum(),
            Value::Object(m) => m.values().map(count).sum(),
            _ => 0,
        }
    }
    fn walk(v: &mut Value, mut n: usize) -> &mut Value {
        if n == 0 {
            return v;
        }
        n -= 1;
        let children: Vec<&mut Value> = match v {
            Value::Array(a) => a.iter_mut().collect(),
            Value::Object(m) => m.values_mut().collect(),
            _ => unreachable!("n is below the count"),
        };
        for c in children {
            let k = count(c);
            if n < k {
                return walk(c, n);
            }
            n -= k;
        }
        unreachable!("n is below the count")
    }
    let n = at as usize % count(v);
    walk(v, n)
}

/// The parent container of node `at` and the child's key or index (none for the root).
fn apply_edit(doc: &mut Value, e: &Edit) {
    match e {
        Edit::Replace(at, v) => *node_mut(doc, *at) = v.clone(),
        Edit::Remove(at) | Edit::Duplicate(at) | Edit::AddKey(at, ..) => {
            let node = node_mut(doc, *at);
            match (node, e) {
                (Value::Object(m), Edit::Remove(_)) if !m.is_empty() => {
                    let k = m.keys().nth(*at as usize % m.len()).unwrap().clone();
                    m.remove(&k);
                }
                (Value::Array(a), Edit::Remove(_)) if !a.is_empty() => {
                    a.remove(*at as usize % a.len());
                }
                (Value::Array(a), Edit::Duplicate(_)) if !a.is_empty() => {
                    let x = a[*at as usize % a.len()].clone();
                    a.push(x);
                }
                (Value::Object(m), Edit::AddKey(_, k, v)) => {
                    m.insert(k.clone(), v.clone());
                }
                _ => {}
            }
        }
    }
}

fn apply_bytes(mut b: Vec<u8>, edits: &[ByteEdit]) -> Vec<u8> {
    for e in edits {
        let at = |a: u32, len: usize| a as usize % (len + 1);
        match e {
            ByteEdit::Flip(a, x) if !b.is_empty() => {
                let i = *a as usize % b.len();
                b[i] ^= x | 1;
            }
            ByteEdit::Truncate(a) => b.truncate(at(*a, b.len())),
            ByteEdit::Insert(a, x) => {
                let i = at(*a, b.len());
                b.splice(i..i, x.iter().copied());
            }
            _ => {}
        }
    }
    b
}

fn mutate_json(seeds: &[Value], m: &Mutation) -> Vec<u8> {
    let mut doc = seeds[m.seed % seeds.len()].clone();
    for e in &m.edits {
        apply_edit(&mut doc, e);
    }
    apply_bytes(serde_json::to_vec_pretty(&doc).unwrap(), &m.bytes)
}

// ---- The runner ----

fn cases() -> u32 {
    std::env::var("GIBENCH_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(256)
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `target` on `bytes` under the bounds; `Err` says which was broken (and saves the input).
fn check(
    name: &str,
    bytes: &[u8],
    target: &dyn Fn(&[u8]) -> bool,
) -> Result<(Duration, isize, bool), String> {
    let began = Instant::now();
    let (outcome, peak) =
        peak_during(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| target(bytes))));
    let took = began.elapsed();
    let accepted = matches!(outcome, Ok(true));
    let broken = match outcome {
        Err(p) => Some(format!(
            "panicked: {}",
            p.downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default()
        )),
        Ok(_) if peak - bytes.len() as isize > ALLOC_BOUND => {
            Some(format!("allocated {peak} bytes at its peak"))
        }
        Ok(_) if took > TIME_BOUND => Some(format!("took {took:?}")),
        Ok(_) => None,
    };
    match broken {
        None => Ok((took, peak, accepted)),
        Some(why) => Err(format!("{name}: {why}")),
    }
}

/// Writes a failing input to `target/fuzz-failures/NAME-HASH.bin`; returns the path.
fn save(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = repo().join("target/fuzz-failures");
    let _ = std::fs::create_dir_all(&dir);
    let file = dir.join(format!("{name}-{:08x}.bin", crc(bytes)));
    let _ = std::fs::write(&file, bytes);
    file
}

fn crc(b: &[u8]) -> u32 {
    b.iter()
        .fold(0x811c9dc5u32, |h, &x| (h ^ x as u32).wrapping_mul(16777619))
}

/// Replays `tests/fuzz-corpus/NAME/`, then runs `cases()` generated inputs; prints the count,
/// how many the target accepted (`target` returns whether the input parsed), the time and the
/// worst time and allocation. The first failure (shrunk by proptest) is saved and reported.
fn campaign<S: Strategy>(
    name: &str,
    strategy: S,
    make: impl Fn(&S::Value) -> Vec<u8>,
    target: &dyn Fn(&[u8]) -> bool,
) {
    // The panics caught while proptest shrinks a failure would flood the output: the failure
    // is reported once, below.
    // `GIBENCH_FUZZ_VERBOSE=1` keeps them (with RUST_BACKTRACE, where a corpus input panics).
    if std::env::var_os("GIBENCH_FUZZ_VERBOSE").is_none() {
        std::panic::set_hook(Box::new(|_| {}));
    }
    let corpus = repo().join("tests/fuzz-corpus").join(name);
    let mut replayed = 0;
    if let Ok(entries) = std::fs::read_dir(&corpus) {
        for e in entries.flatten() {
            let bytes = std::fs::read(e.path()).unwrap();
            if let Err(why) = check(name, &bytes, target) {
                eprintln!("corpus {}: {why}", e.path().display());
                panic!("corpus {}: {why}", e.path().display());
            }
            replayed += 1;
        }
    }
    let n = cases();
    let mut runner = TestRunner::new(Config {
        cases: n,
        failure_persistence: None,
        ..Config::default()
    });
    let began = Instant::now();
    let worst = std::cell::RefCell::new((Duration::ZERO, 0isize, 0u64));
    let outcome = runner.run(&strategy, |v| {
        let bytes = make(&v);
        let (t, a, ok) = check(name, &bytes, target).map_err(TestCaseError::fail)?;
        let mut w = worst.borrow_mut();
        *w = (w.0.max(t), w.1.max(a), w.2 + ok as u64);
        Ok(())
    });
    let (t, a, accepted) = *worst.borrow();
    println!(
        "fuzz {name}: {n} inputs (+{replayed} from the corpus), {accepted} accepted, in {:.1} s; \
         slowest {:.2} ms, largest allocation peak {:.2} MiB",
        began.elapsed().as_secs_f64(),
        t.as_secs_f64() * 1e3,
        a as f64 / (1 << 20) as f64
    );
    if let Err(e) = outcome {
        let saved = match &e {
            proptest::test_runner::TestError::Fail(_, v) => {
                format!("; the input is saved to {}", save(name, &make(v)).display())
            }
            _ => String::new(),
        };
        eprintln!("{e}{saved}");
        panic!("{e}{saved}");
    }
}

fn read_json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn json_files(dir: &Path, take: usize) -> Vec<Value> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files.iter().take(take).map(|p| read_json(p)).collect()
}

// ---- Targets ----

mod targets;
