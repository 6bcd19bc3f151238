"""Per-seed generations to the threshold (N: not reached) and late rewards, from a combined report's summary.json."""
import json, sys

d = json.load(open(sys.argv[1]))
budget = d["budget_generations"]
print("| seed | " + " | ".join(str(i) for i in range(10)) + " |")
print("|---|" + "---|" * 10)
for m, v in d["methods"].items():
    t = v["to_threshold"]
    cells = [str(int(g)) if r else "N" for g, r in zip(t["generations"]["per_seed"], t["reached"])]
    print(f"| {m} | " + " | ".join(cells) + " |")
print()
print("late reward per seed (mean of the last 10 tests):")
for m, v in d["methods"].items():
    print(f"| {m} | " + " | ".join(f"{x:.2f}" for x in v["late_test_reward_per_seed"]) + " |")
