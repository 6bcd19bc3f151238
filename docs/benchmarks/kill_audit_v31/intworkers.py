import subprocess, sys, time, signal, os, shutil
name, delay = sys.argv[1], float(sys.argv[2])
shutil.rmtree(name, ignore_errors=True)
p = subprocess.Popen(["shaped-es","train","--env","PointVel-v0","--method","shaped","--generations","8","--seed","3","--out",name,"--executor","process","--workers","2","--set","tensorboard=false"], stdout=open(f"logs/{name}.train.out","w"), stderr=subprocess.STDOUT)
t0=time.time()
def desc():
    rows=[l.split() for l in subprocess.run(["ps","-eo","pid,ppid"],capture_output=True,text=True).stdout.split("\n")[1:] if l.strip()]
    d={p.pid}
    for _ in range(4): d|={int(a) for a,b in rows if int(b) in d}
    d.discard(p.pid); return d
while p.poll() is None:
    if len(desc())>=3: break
    time.sleep(0.005)
t1=time.time()-t0; time.sleep(delay); p.send_signal(signal.SIGINT); rc=p.wait()
out=open(f"logs/{name}.train.out").read()
print(f"{name}: workers seen at {t1:.2f}s, INT +{delay}s, rc={rc}, tracebacks={out.count('Traceback')}, lines={out.count(chr(10))}")
