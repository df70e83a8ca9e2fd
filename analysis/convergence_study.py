"""Issue 15 defect 1: does the creep verdict depend on the integrator accuracy?

Paper preset, one friction law, a few feeds (mm/s), one load case; runge_kutta3 at 1e-4, 1e-5, 1e-6,
convergence check off (this measures the raw integrator). 3 s runs, metrics over t >= 1 s.
Run: python analysis/convergence_study.py stribeck 0.5,0.6,1.0 3
     python analysis/convergence_study.py lugre 0.05,0.1,0.5 3
"""
import sys
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
law = sys.argv[1]; feeds=[float(f) for f in sys.argv[2].split(",")]; lc=int(sys.argv[3]) if len(sys.argv)>3 else 3
p = with_value(preset("paper"), "friction.law", law)
for feed in feeds:
    for integ, acc in [("runge_kutta3",1e-4),("runge_kutta3",1e-5),("runge_kutta3",1e-6)]:
        q = with_value(with_value(with_value(p,"simulation.integrator",integ),"simulation.accuracy",acc),"simulation.convergence_check",False)
        r = simulate(q, Scenario(feed=feed*1e-3, load_case=lc, duration=3.0))
        m=r.metrics
        print(f"{law} feed {feed} lc{lc} {integ} {acc:g}: creep={m.creep} cyc={m.stick_slip_cycles} stick={m.stick_fraction:.3f} fluct={m.fluctuation_rate*100:.1f}% wall={r.wall_time:.2f}s steps={r.stats['steps']} {r.status}", flush=True)
