import csv, sys, math
def load(p):
    with open(p, newline='') as f:
        return list(csv.DictReader(f))
a, b = load(sys.argv[1]), load(sys.argv[2])
def ign(c): return c.endswith('_s') or c.startswith('time_') or 'time' in c
cols_a = list(a[0].keys()) if a else []
cols_b = list(b[0].keys()) if b else []
if cols_a != cols_b: print("COLUMNS DIFFER", set(cols_a)^set(cols_b))
ok = True
if len(a) != len(b): print(f"ROWCOUNT ref={len(a)} got={len(b)}"); ok=False
for i,(ra,rb) in enumerate(zip(a,b)):
    for c in cols_a:
        if ign(c): continue
        if ra.get(c) != rb.get(c):
            print(f"DIFF row {i} (generation {ra.get('generation')}/{rb.get('generation')}) col {c}: ref={ra.get(c)} got={rb.get(c)}"); ok=False; break
    if not ok: break
print("MATCH" if ok else "MISMATCH", len(a), len(b))
