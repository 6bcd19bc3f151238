import re, csv, json, glob, os
lines = open("logs/bench_a.log").read().splitlines() + open("logs/bench_b.log").read().splitlines()
bench = {}
probe = {}
gen0 = {}
notes = {}
for l in lines:
    m = re.match(r"\[benchmark\] (\w+)_s(\d+): new \(([\d.]+) s\), test ([\d.-]+), 8.37 reached at generation (\d+)(.*)", l)
    if m:
        meth, s = m.group(1), int(m.group(2))
        tail = m.group(6)
        acc = re.search(r"accepted (\d+) of (\d+) judged", tail)
        none = re.search(r"no candidate accepted in (\d+) judged", tail)
        bench[(meth, s)] = dict(call_s=float(m.group(3)), final=float(m.group(4)), gen=int(m.group(5)),
                                acc=(f"{acc.group(1)}/{acc.group(2)}" if acc else (f"0/{none.group(1)}" if none else "")))
    m = re.match(r"shaped-es: (\w+)_s(\d+): labels: (.*)", l)
    if m: probe[(m.group(1), int(m.group(2)))] = m.group(3)
    m = re.match(r"shaped-es: (\w+)_s(\d+): generation 0: the label probe's best simulated candidate \((.*?)\) (won|lost)", l)
    if m: gen0[(m.group(1), int(m.group(2)))] = m.group(4)
    m = re.match(r"shaped-es: (\w+)_s(\d+): note: labels lost 8 judged generations in a row \(won (\d+) of (\d+)\)", l)
    if m: notes[(m.group(1), int(m.group(2)))] = f"won {m.group(3)} of {m.group(4)}"
def wall(meth, s):
    d = glob.glob(f"bench_*/runs/{meth}_s{s}")[0]
    rows = list(csv.DictReader(open(f"{d}/metrics.csv")))
    return float(rows[-1]["wall_time_s"])
print("| seed | " + " | ".join(f"{m} gens" for m in ["shaped","vanilla","cmaes","oracle"]) + " |")
print("|---|---|---|---|---|")
for s in range(10):
    print(f"| {s} | " + " | ".join(str(bench[(m,s)]["gen"]) for m in ["shaped","vanilla","cmaes","oracle"]) + " |")
print()
print("| seed | " + " | ".join(f"{m} final test" for m in ["shaped","vanilla","cmaes","oracle"]) + " |")
print("|---|---|---|---|---|")
for s in range(10):
    print(f"| {s} | " + " | ".join(f'{bench[(m,s)]["final"]:.2f}' for m in ["shaped","vanilla","cmaes","oracle"]) + " |")
print()
print("| seed | " + " | ".join(f"{m} wall_time_s / call s" for m in ["shaped","vanilla","cmaes","oracle"]) + " |")
print("|---|---|---|---|---|")
for s in range(10):
    print(f"| {s} | " + " | ".join(f'{wall(m,s):.1f} / {bench[(m,s)]["call_s"]:.1f}' for m in ["shaped","vanilla","cmaes","oracle"]) + " |")
print()
print("| seed | shaped accepted/judged | oracle accepted/judged | shaped gen-0 probe candidate | shaped back-off note | oracle back-off note | shaped probe line |")
print("|---|---|---|---|---|---|---|")
for s in range(10):
    print(f"| {s} | {bench[('shaped',s)]['acc']} | {bench[('oracle',s)]['acc']} | {gen0.get(('shaped',s),'')} | {notes.get(('shaped',s),'none')} | {notes.get(('oracle',s),'none')} | {probe.get(('shaped',s),'')} |")
