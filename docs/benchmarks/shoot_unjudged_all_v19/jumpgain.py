"""Per run: fresh-test change after accepted jumps vs after other awake generations."""
import csv,glob,sys,os,numpy as np
def stats(run, thr=None):
    rows=list(csv.DictReader(open(run+'/metrics.csv')))
    t=[float(x['test_reward_mean']) if x['test_reward_mean'] not in ('',None) else np.nan for x in rows]
    acc=[x.get('candidate_accepted')=='1' for x in rows]
    awake=[x.get('shaping_awake')=='1' for x in rows]
    da=[];do=[];dv=[]
    for g in range(len(rows)-1):
        d=t[g+1]-t[g]
        if np.isnan(d): continue
        if acc[g]: da.append((g,d))
        elif awake[g]: do.append(d)
        dv.append(d)
    return da,do,t
for pat in sys.argv[1:]:
    runs=sorted(glob.glob(pat))
    if not runs: continue
    allacc=[];allo=[];per=[]
    for r in runs:
        da,do,t=stats(r)
        a=[d for g,d in da]
        allacc+=a;allo+=do
        # spread: std of test rewards over the run's last half
        per.append((os.path.basename(r),len(a),np.mean(a) if a else np.nan,np.mean(a[:8]) if a else np.nan,np.mean(do) if do else np.nan, np.nanstd(np.diff(t))))
    print(pat, 'jumps %d mean %.3f | other awake %d mean %.3f'%(len(allacc),np.mean(allacc) if allacc else np.nan,len(allo),np.mean(allo) if allo else np.nan))
    for p in per: print('   %-12s n=%3d acc=%.3f first8=%.3f other=%.3f sd(dtest)=%.3f'%p)
