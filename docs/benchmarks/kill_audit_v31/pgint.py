import subprocess, sys, time, signal, os, shutil
name, T, ex = sys.argv[1], float(sys.argv[2]), sys.argv[3]
shutil.rmtree(name, ignore_errors=True)
p = subprocess.Popen(["shaped-es","train","--env","PointVel-v0","--method","shaped","--generations","8","--seed","3","--out",name,"--executor",ex,"--workers","2","--set","tensorboard=false"], stdout=open(f"logs/{name}.train.out","w"), stderr=subprocess.STDOUT, start_new_session=True)
time.sleep(T); os.killpg(p.pid, signal.SIGINT); rc=p.wait(); time.sleep(1)
out=open(f"logs/{name}.train.out").read()
alive=subprocess.run(["pgrep","-g",str(p.pid)],capture_output=True,text=True).stdout.split()
print(f"{name}: Ctrl-C to process group at {T}s ({ex}), rc={rc}, tracebacks={out.count('Traceback')}, lines={out.count(chr(10))}, group procs left={alive}")
