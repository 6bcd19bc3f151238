import csv,sys,glob,os
for d in sys.argv[1:]:
    tot=[];acc=[];jud=[];chk=[];wall=[];reach=[]
    for r in sorted(glob.glob(d+'/runs/*/metrics.csv')):
        rows=list(csv.DictReader(open(r)))
        tot.append(sum(1 for x in rows if x.get('shaping_awake')=='1'))
        acc.append(sum(1 for x in rows if x.get('candidate_accepted')=='1'))
        jud.append(sum(1 for x in rows if x.get('candidate_accepted') in ('0','1')))
        chk.append(sum(1 for x in rows if x.get('check_env_steps') not in (None,'','0')))
        wall.append(float(rows[-1]['wall_time_s']))
    print(d,'awake',tot,sum(tot)/len(tot),'acc',sum(acc),'judged',sum(jud),'checks',sum(chk),'wall',round(sum(wall)/len(wall),1))
