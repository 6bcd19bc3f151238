"""What M_phi and the servo were trained on in a Turn-v0 shaped run (before pruning it):
    shaped-es train --env turn:Turn-v0 --method shaped --generations 2 --executor inline --quiet --out runs/peek_v0
    python peek_mphi.py runs/peek_v0        # then: shaped-es prune runs/peek_v0
The last input column of mphi_data's x is taken to be the 1-D displacement p_{t+1} - p_t (its range says so)."""
import sys
import numpy as np

run = sys.argv[1] if len(sys.argv) > 1 else "runs/peek_v0"
m = np.load(f"{run}/mphi_data/added_000001.npz")
v = np.load(f"{run}/mphi_data_servo/added_000001.npz")
dp = m["x"][:, -1]
big = np.abs(dp) > np.pi
print(f"M_phi rows: {len(dp)}; |dp| > pi: {big.sum()} ({100 * big.mean():.2f}%), e.g. {np.round(dp[big][:6], 3)}")
print(f"std of dp {dp.std():.3f}, without those rows {dp[~big].std():.3f}; median |dp| {np.median(np.abs(dp)):.4f}")
print("servo rows aligned with M_phi's:", np.allclose(m["x"][:, :-1], v["x"][:, :-1]))
ys = v["y"][:, 0]
print(f"servo targets saturated at 0.99: {(np.abs(ys) >= 0.989).sum()}; on the jump rows: {np.round(ys[big][:8], 2)}; "
      f"same sign as the jump: {np.mean(np.sign(ys[big]) == np.sign(dp[big])):.2f}")
