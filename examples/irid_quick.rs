fn main() {
    use snakeskin::optics::accuracy::*;
    use snakeskin::optics::methods::Method;
    let t = std::time::Instant::now();
    let r = bench_irid(10.0, 1.0, &Method::all_realtime());
    for m in r {
        println!(
            "{:<14} mean {:6.3} p95 {:6.3} max {:6.3} ns {:8.1}",
            m.name, m.mean_de, m.p95_de, m.max_de, m.ns_per_eval
        );
    }
    println!("{:?}", t.elapsed());
}
