#!/usr/bin/env python3
# Offline experiment (not part of the library): would dividing each log's features by that log's
# own per-feature standard deviation (unsupervised, no labels) let boosted stumps transfer across
# environments? Reads the features.csv files that `urbanslam eval-laser-loop MODEL LOG --out
# /tmp/ll/feat-NAME` writes (features with the model's gates), labels pairs with the same rules
# as the C++ code (1 m / 3 m / 10 m travel, ≤ 3000 positives, balanced training, 10 negatives per
# positive for testing), runs Algorithm 1 for T = 60 in plain Python and prints the detection at
# 0.1 % and 1 % false alarm with raw and with per-log-scaled features.
#
#   for f in intel aces csail freiburg-campus fhw; do build-laser/apps/urbanslam/urbanslam \
#     eval-laser-loop share/laser_loop/default.model \
#     ../shared/data/freiburg_slam_benchmark/corrected_logs/$f-corrected.log.gz --quiet --out /tmp/ll/feat-$f; done
#   bench/laser_loop/per_log_scaling_experiment.py intel,aces,csail freiburg-campus [30]
import csv, math, random, sys, bisect
def load(name):
    rows=list(csv.DictReader(open(f'/tmp/ll/feat-{name}/features.csv')))
    keys=[k for k in rows[0] if k not in ('log','scan','timestamp','x','y','phi')]
    F=[[float(r[k]) for k in keys] for r in rows]
    P=[(float(r['x']),float(r['y']),float(r['phi'])) for r in rows]
    return F,P
def pairs(P, rng, nneg_per=1, maxpos=3000, dpos=1, dneg=3, travel=10, maxh=math.pi):
    path=[0]
    for i in range(1,len(P)): path.append(path[-1]+math.hypot(P[i][0]-P[i-1][0],P[i][1]-P[i-1][1]))
    pos=[(i,j,1) for i in range(len(P)) for j in range(i+1,len(P)) if math.hypot(P[i][0]-P[j][0],P[i][1]-P[j][1])<=dpos and path[j]-path[i]>=travel and abs((P[i][2]-P[j][2]+math.pi)%(2*math.pi)-math.pi)<=maxh]
    rng.shuffle(pos); pos=pos[:maxpos]
    neg=set()
    want=max(int(nneg_per*len(pos)), 0)
    while len(neg)<want:
        i=rng.randrange(len(P)); j=rng.randrange(len(P))
        if i<j and math.hypot(P[i][0]-P[j][0],P[i][1]-P[j][1])>dneg: neg.add((i,j,0))
    return pos+list(neg)
def scale(F, on):
    if not on: return F
    n=len(F); m=len(F[0]); out=[r[:] for r in F]
    for k in range(m):
        mu=sum(r[k] for r in F)/n; sd=math.sqrt(sum((r[k]-mu)**2 for r in F)/(n-1)) or 1
        for r in out: r[k]/=sd
    return out
def table(F, prs): return [[abs(F[i][k]-F[j][k]) for k in range(len(F[0]))] for i,j,_ in prs], [y for *_,y in prs]
def adaboost(X,y,T):
    n=len(y); m=len(X[0]); npos=sum(y); nneg=n-npos
    w=[1/(2*npos) if yi else 1/(2*nneg) for yi in y]
    order=[sorted(range(n), key=lambda i:X[i][k]) for k in range(m)]
    H=[]
    for t in range(T):
        s=sum(w); w=[x/s for x in w]
        best=(2,None)
        for k in range(m):
            o=order[k]; wp=sum(w[i] for i in o if y[i]); wn=1-wp
            nb=pb=0
            for c in range(n+1):
                if c>0:
                    i=o[c-1]
                    if y[i]: pb+=w[i]
                    else: nb+=w[i]
                if 0<c<n and not X[o[c-1]][k]<X[o[c]][k]: continue
                thr = X[o[0]][k]-1 if c==0 else (X[o[n-1]][k]+1 if c==n else (X[o[c-1]][k]+X[o[c]][k])/2)
                e=nb+(wp-pb)
                if e<best[0]: best=(e,(k,thr,1))
                if 1-e<best[0]: best=(1-e,(k,thr,-1))
        e,(k,thr,pol)=best
        e=max(e,1e-10); b=e/(1-e)
        for i in range(n):
            pred = X[i][k]<thr if pol>0 else X[i][k]>thr
            if pred==bool(y[i]): w[i]*=b
        H.append((k,thr,pol,math.log(1/b)))
    return H
def score(H,x):
    tot=sum(a for *_,a in H); v=sum(a for k,thr,pol,a in H if (x[k]<thr if pol>0 else x[k]>thr))
    return v/tot
def det_at(ps,ns,fa):
    ns=sorted(ns,reverse=True); k=int(fa*len(ns)); bar=ns[k] if k<len(ns) else -1e300
    return sum(1 for s in ps if s>bar)/len(ps)
rng=random.Random(1)
train=sys.argv[1].split(','); test=sys.argv[2].split(',')
# Optional third argument: heading limit (degrees) for the training positives; tests use any heading.
maxh=math.radians(float(sys.argv[3])) if len(sys.argv)>3 else math.pi
for on in (False, True):
    X=[];y=[]
    for nme in train:
        F,P=load(nme); F=scale(F,on); prs=pairs(P,rng,maxh=maxh); a,b=table(F,prs); X+=a; y+=b
    H=adaboost(X,y,60)
    ps=[];ns=[];nps=[];nns=[]
    for nme in test:
        F,P=load(nme); F=scale(F,on); prs=pairs(P,rng,nneg_per=10)
        for (i,j,l) in prs:
            x=[abs(F[i][k]-F[j][k]) for k in range(len(F[0]))]
            (ps if l else ns).append(score(H,x))
    print('per-log scaling' if on else 'raw features', 'train',train,'test',test,'pos',len(ps),'det@0.1%',round(det_at(ps,ns,0.001),3),'det@1%',round(det_at(ps,ns,0.01),3))
