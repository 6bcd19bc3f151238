import csv,glob,sys,json,numpy as np
def first(path,thr):
    r=list(csv.DictReader(open(path)))
    return next((int(x['generation']) for x in r if x['test_reward_mean'] and float(x['test_reward_mean'])>=thr),None), len(r)
def late(path):
    r=list(csv.DictReader(open(path))); t=[float(x['test_reward_mean']) for x in r if x['test_reward_mean']]
    return float(np.mean(t[-10:]))
def wall(path):
    return float(list(csv.DictReader(open(path)))[-1]['wall_time_s'])
thr=float(sys.argv[1])
for d in sys.argv[2:]:
    runs=sorted(glob.glob(d+'/metrics.csv'))
    g=[];L=[];W=[]
    for r in runs:
        f,n=first(r,thr); g.append(f if f is not None else n+1); L.append(late(r)); W.append(wall(r))
    solved=sum(1 for r in runs if first(r,thr)[0] is not None)
    print(d, 'n',len(runs),'solved',solved,'gens',g,'mean %.1f'%np.mean(g),'late %.2f'%np.mean(L),'wall %.1f'%np.median(W))
