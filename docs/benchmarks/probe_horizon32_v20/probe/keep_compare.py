import json, sys, collections, statistics as st
rows = [json.loads(l) for f in sys.argv[1:] for l in open(f) if l.startswith("{")]
full = {(r["env"], r["seed"]): r for r in rows if r["keep"] == 0}
F = ["frame", "clip", "chunk", "shoot_on", "horizon", "candidate", "unjudged", "third", "base"]
for K in sorted({r["keep"] for r in rows} - {0}):
    print(f"== keep {K}")
    per = collections.defaultdict(list)
    for r in rows:
        if r["keep"] != K or (r["env"], r["seed"]) not in full: continue
        f = full[(r["env"], r["seed"])]
        diff = [k for k in F if r[k] != f[k]]
        per[r["env"]].append((r["steps"] / f["steps"], r["sec"] / f["sec"], diff, r["seed"], f, r))
    tot = 0; nd = 0
    for env, L in per.items():
        d = [(s, x) for _, _, x, s, *_ in L if x]
        tot += len(L); nd += len(d)
        print(f"{env:28s} n={len(L):2d} steps {st.median(l[0] for l in L):.2f} sec {st.median(l[1] for l in L):.2f} changed {len(d)}: "
              + "; ".join(f"s{s}:" + ",".join(f"{k}={L2[5][k]}<-{L2[4][k]}" for k in x) for (s, x) in d for L2 in L if L2[3] == s))
    print("changed", nd, "of", tot)
