# usage: python killat.py NAME SIG PATH_GLOB DELAY GENS [extra train args]
import sys, subprocess, glob, time, os, signal
name, sig, pat, delay, gens = sys.argv[1:6]; extra = sys.argv[6:]
import shutil
env = os.environ.copy()
if not env.get("RESUME") and not env.get("KEEP"): shutil.rmtree(name, ignore_errors=True)
cmd = ["shaped-es","train","--env",env.get("ENV","PointVel-v0"),"--method",env.get("METHOD","shaped"),"--generations",gens,"--seed",env.get("SEED","3"),"--out",name,"--executor",env.get("EXEC","inline"),"--set","tensorboard=false"]+extra
if env.get("BENCH"): cmd=["shaped-es","benchmark","--env","PointVel-v0","--methods","shaped,vanilla","--seeds","2","--generations","6","--out",name,"--executor","inline","--set","tensorboard=false"]
if env.get("RESUME"): cmd=["shaped-es","resume",name]+extra
os.makedirs("logs", exist_ok=True)
out = open(f"logs/{name}.{'resume' if env.get('RESUME') else 'train'}.out","a")
p = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, start_new_session=False)
t0 = time.time()
while p.poll() is None:
    if (pat.startswith("T=") and time.time()-t0>=float(pat[2:])) or (not pat.startswith("T=") and glob.glob(os.path.join(name, pat))):
        t = time.time()-t0
        if float(delay) > 0: time.sleep(float(delay))
        import subprocess as sp
        rows=[l.split() for l in sp.run(["ps","-eo","pid,ppid"],capture_output=True,text=True).stdout.split("\n")[1:] if l.strip()]
        desc={p.pid}
        for _ in range(5):
            desc |= {int(a) for a,b in rows if int(b) in desc}
        desc.discard(p.pid); open(f"logs/{name}.children","w").write(" ".join(map(str,sorted(desc))))
        p.send_signal(getattr(signal, "SIG"+sig)); break
    time.sleep(0.0005)
rc = p.wait()
print(f"killed at {time.time()-t0:.3f}s after {pat} (+{delay}); rc={rc}")
