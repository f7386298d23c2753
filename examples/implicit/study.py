#!/usr/bin/env python3
"""V7 study of the implicit solver (001, section 3): every problem run with the explicit solver
and with the implicit one at several time-step multiples, in one session on one thread.

Writes into study/:
  tables.md           cost tables in the seed's form (Tables 1-6) with accuracy columns,
                      the options table (forcing x preconditioner), the bar stresses,
                      the disks' dissipation, the upsetting's loads and radii
  summary.json        every number of the tables
  disks_energy.png    kinetic, strain and total energy of the colliding disks
  upsetting_load.png  load-deflection: explicit and implicit at each multiple; three meshes
  cost_error.png      cost ratio (wall time and residual evaluations) and error vs dt multiple
  *.csv, *.mpm        histories, particle dumps and result streams of every run

Usage: study.py BUILD_DIR [--quick]   (--quick: skips the 1x and 10x upsetting and the
finest mesh, for a look in a minute)
"""
import csv
import json
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, 'study')

# The seed's cost ratios (001, Tables 1-6): (table, solver) -> {(multiple, ramp): ratio}.
# Ramp a: from the explicit step up; c: from 100 explicit steps up (Table 6: constant).
SEED = {
    ('elastic_bar', 'cg'): {(1, 'a'): 1.7294, (10, 'a'): 0.3444, (100, 'a'): 0.1149, (100, 'c'): 0.0834},
    ('elastic_bar', 'gmres'): {(1, 'a'): 1.9796, (10, 'a'): 0.3625, (100, 'a'): 0.0966, (100, 'c'): 0.0611},
    ('plastic_bar', 'cg'): {(1, 'a'): 1.8600, (10, 'a'): 0.4241, (100, 'a'): 0.1843, (100, 'c'): 0.1844},
    ('plastic_bar', 'gmres'): {(1, 'a'): 1.9495, (10, 'a'): 0.5636, (100, 'a'): 0.1059, (100, 'c'): 0.0909},
    ('disks', 'cg'): {(1, 'a'): 3.2347, (10, 'a'): 2.8845, (100, 'a'): 0.5265, (100, 'c'): 0.5917},
    ('upsetting', 'gmres'): {(1, 'k'): 3.0120, (10, 'k'): 1.1707, (100, 'k'): 0.2998,
                             (1000, 'k'): 0.0587, (10000, 'k'): 0.0115},
}
# Seed tolerances per problem (sections 3.1.1, 3.1.2, 3.2.5-3.2.7). The upsetting's 1e-4 is for
# a residual scaled in millimetres: 0.1 in SI (see docs/scene.md, "The residual").
TOL = {
    'elastic_bar': (1e-5, 1e-3),
    'plastic_bar': (1e-6, 1e-4),
    'disks': (1e-5, 1e-3),
    'upsetting': (0.1, 1e-2),
}


def sh(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


class Tools:
    def __init__(self, build):
        self.prep = os.path.join(build, 'mpm-prep', 'mpm-prep')
        self.run = os.path.join(build, 'mpm-run', 'mpm-run')
        self.post = os.path.join(build, 'mpm-post', 'mpm-post')

    def model(self, scene, name, sets=()):
        path = os.path.join(OUT, name + '.model')
        args = [self.prep, os.path.join(HERE, scene), '-o', path]
        for s in sets:
            args += ['--set', s]
        r = sh(args)
        if r.returncode != 0:
            sys.exit(f'mpm-prep failed for {name}: {r.stderr}')
        return path

    def simulate(self, model, name, sets=(), repeat=1):
        """Runs mpm-run on one thread; the wall time is the best of `repeat` runs (the small
        problems take milliseconds, where other processes on the machine add noise)."""
        stream = os.path.join(OUT, name + '.mpm')
        args = [self.run, model, '-o', stream, '--threads', '1', '--stats', '--progress', 'none',
                '--set', 'output.frames=1']
        for s in sets:
            args += ['--set', s]
        best = None
        for _ in range(repeat):
            r = sh(args)
            m = re.search(r'implicit: explicit dt ([0-9.e+-]+) s, steps (\d+), newton (\d+), krylov (\d+), '
                          r'residual evaluations (\d+), line-search cuts (\d+), step cuts (\d+) \(lagrangian (\d+)\), '
                          r'wall ([0-9.e+-]+) s', r.stderr)
            e = re.search(r'explicit: steps (\d+), wall ([0-9.e+-]+) s', r.stderr)
            if r.returncode != 0 or not (m or e):
                return {'name': name, 'status': r.returncode, 'message': r.stderr.strip().splitlines()[-1:]}
            if m:
                res = dict(zip(['explicit_dt', 'steps', 'newton', 'krylov', 'evals', 'ls_cuts', 'step_cuts',
                                'lagrangian_cuts', 'wall'], [float(x) for x in m.groups()]))
            else:
                res = {'steps': float(e.group(1)), 'wall': float(e.group(2))}
            if best is None or res['wall'] < best['wall']:
                best = res
        best.update(name=name, status=0, stream=stream)
        hist = os.path.join(OUT, name + '_history.csv')
        sh([self.post, 'history', stream, '-o', hist])
        best['history'] = read_csv(hist)
        part = os.path.join(OUT, name + '_particles.csv')
        sh([self.post, 'particles', stream, '-o', part, '--columns', 'x,sigma,material'])
        best['particles'] = read_csv(part)
        return best


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith('#')))
    return [{k: float(v) for k, v in zip(rows[0], r)} for r in rows[1:]]


def material(rows):
    return [r for r in rows if r['material'] != 255]


def sxx(run):
    s = [r['sigma_0'] for r in material(run['particles'])]
    return sum(s) / len(s), min(s), max(s)


def nodal_sxx(tools, run):
    """sigma_xx on the mesh as the seed graphs it (001, Fig. 1b): `mpm-post profile --grid`
    (the bar's particles projected onto the grid nodes, mass-weighted, with the solver's shape
    functions) at the bar's interior nodes, x = 0.4 ... 0.7 on the rows y = 0.2 and 0.3.
    Returns (mean, min, max) over those nodes."""
    v = []
    for y in (0.2, 0.3):
        r = sh([tools.post, 'profile', run['stream'], '--grid', '--body', 'bar', '--field', 'sigma',
                '--component', 'xx', '--from', f'0.4 {y}', '--to', f'0.7 {y}', '--radius', '1e-6'])
        if r.returncode != 0:
            sys.exit(f'mpm-post profile --grid failed: {r.stderr}')
        rows = list(csv.DictReader(r.stdout.splitlines()))
        v += [float(row['value']) for row in rows]
    return sum(v) / len(v), min(v), max(v)


def r_max_mm(run):
    return max(r['x_0'] for r in material(run['particles'])) * 1e3


def binned_load(run, width=0.5):
    """Mean platen load (kN) in bins of platen travel (mm), time-weighted; the last bin closes
    at the end of the run. The material pushes the platen up: +y."""
    rows = run['history']
    end = rows[-1]['time'] * 1e3
    bins = {}
    for r in rows[1:]:
        k = min(int(r['time'] * 1e3 / width), int(end / width - 1e-9))
        b = bins.setdefault(k, [0.0, 0.0])
        b[0] += r['dt'] * r['force_platen_y'] / 1e3
        b[1] += r['dt']
    return {k: b[0] / b[1] for k, b in bins.items() if b[1] > 0}


def load_error(ref, run):
    a, b = binned_load(ref), binned_load(run)
    keys = sorted(k for k in a if k in b and a[k] > 0)
    rms = math.sqrt(sum((b[k] - a[k]) ** 2 for k in keys) / sum(a[k] ** 2 for k in keys))
    return rms, b[keys[-1]]


def energy(run):
    rows = run['history']
    return rows[0]['total'], rows[-1]['total']


def fmt(x, digits=4):
    if x is None:
        return '-'
    if isinstance(x, str):
        return x
    if x == 0:
        return '0'
    if abs(x) >= 1e5 or abs(x) < 1e-3:
        return f'{x:.3g}'
    return f'{x:.{digits}g}'


# ------------------------------------------------------------------------------------------

def uniaxial_law(problem, t):
    """sigma_xx of the bar in uniaxial stress at time t (strain v t / L = 0.001 t / 0.3): the
    seed's eq. 3.1.1, E eps, and for the plastic bar A + E B / (E + B) (eps - A / E)."""
    E, eps = 1000.0, 0.001 * t / 0.3
    if problem == 'elastic_bar':
        return E * eps
    A, B = 6.0, 5000.0
    return A + E * B / (E + B) * (eps - A / E) if eps > A / E else E * eps


def study(tools, quick):
    os.makedirs(OUT, exist_ok=True)
    results = {'tables': {}, 'bars': {}, 'disks': {}, 'upsetting': {}, 'options': []}
    md = ['# V7 study: implicit against explicit (generated by study.py)', '',
          'One thread, one session, one build. "wall" is the time loop of mpm-run (best of 5 runs '
          'for the runs under a second). Cost ratios are against the explicit run of the same '
          'scene: **wall** = wall time ratio, **ops** = residual evaluations / explicit steps '
          '(an explicit step and a residual evaluation are each one particle pass with a '
          'scatter). "seed" is the seed\'s flop ratio (001, Tables 1-6) for the same multiple and '
          'ramp: a = ramped by 20% a step from the explicit step, c = from 100 explicit steps, '
          'k = constant from the start.', '']

    def table(problem, solver, model, ref, cases, error_of, error_name, extra_sets=()):
        newton, linear = TOL[problem]
        form = 'velocity' if solver == 'cg' else 'momentum'
        key = f'{problem}/{solver}'
        rows = []
        md.append(f'### {problem}, Newton-{solver.upper()} ({form} formulation; Newton {newton:g}, '
                  f'linear {linear:g}, h 1e-5)')
        md.append('')
        md.append('| dt multiple | ramp | dt (s) | steps | Newton | Krylov | residual evals | line-search cuts '
                  '| step cuts | wall (s) | wall ratio | ops ratio | seed ratio | ' + error_name + ' |')
        md.append('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
        md.append(f'| explicit | | {fmt(ref["explicit_dt"])} | {int(ref["steps"])} | | | | | | '
                  f'{fmt(ref["wall"])} | 1 | 1 | 1 | {fmt(error_of(ref, ref))} |')
        for mult, ramp in cases:
            # ramp a, c or k; a trailing t: the same with preconditioner = "tangent"
            initial = {'a': 1, 'c': 100, 'k': mult}[ramp[0]]
            initial = min(initial, mult)
            sets = ['solver.type=implicit', f'solver.implicit.formulation={form}',
                    f'solver.implicit.newton_tolerance={newton}', f'solver.implicit.linear_tolerance={linear}',
                    f'solver.implicit.dt_initial_multiple={initial}', f'solver.implicit.dt_target_multiple={mult}']
            sets += list(extra_sets)
            if ramp.endswith('t'):
                sets.append('solver.implicit.preconditioner=tangent')
            name = f'{problem}_{solver}_{mult}{ramp}'
            r = tools.simulate(model, name, sets, repeat=5 if ref['wall'] < 1 else 1)
            seed = SEED.get((problem, solver), {}).get((mult, ramp[0]))
            if r['status'] != 0:
                md.append(f'| {mult} | {ramp} | | failed: {" ".join(r["message"])} | | | | | | | | | {fmt(seed)} | |')
                rows.append({'multiple': mult, 'ramp': ramp, 'status': r['status']})
                continue
            wall_ratio, ops_ratio = r['wall'] / ref['wall'], r['evals'] / ref['steps']
            err = error_of(ref, r)
            md.append(f'| {mult} | {ramp} | {fmt(mult * r["explicit_dt"])} | {int(r["steps"])} | {int(r["newton"])} '
                      f'| {int(r["krylov"])} | {int(r["evals"])} | {int(r["ls_cuts"])} | {int(r["step_cuts"])} '
                      f'| {fmt(r["wall"])} | {fmt(wall_ratio)} | {fmt(ops_ratio)} | {fmt(seed)} | {fmt(err)} |')
            rows.append({k: r[k] for k in ('steps', 'newton', 'krylov', 'evals', 'ls_cuts', 'step_cuts', 'wall')}
                        | {'multiple': mult, 'ramp': ramp, 'wall_ratio': wall_ratio, 'ops_ratio': ops_ratio,
                           'seed': seed, 'error': err})
            results.setdefault('runs', {})[name] = r
        md.append('')
        results['tables'][key] = {'explicit': {k: ref[k] for k in ('steps', 'wall', 'explicit_dt')}, 'rows': rows}

    def explicit(model, name, repeat):
        r = tools.simulate(model, name + '_explicit', [], repeat=repeat)
        if r['status'] != 0:
            sys.exit(f'explicit run {name} failed: {r["message"]}')
        # The explicit step the multiples refer to (the implicit solver's reference).
        probe = tools.simulate(model, name + '_probe', ['solver.type=implicit', 'solver.max_steps=1'])
        r['explicit_dt'] = probe['explicit_dt']
        return r

    # Bars ------------------------------------------------------------------------------------
    bar_cases = [(1, 'a'), (10, 'a'), (100, 'a'), (100, 'c')]
    for problem, scene, t_nominal in (('elastic_bar', 'elastic_bar.toml', 10.0),
                                      ('plastic_bar', 'plastic_bar.toml', 24.0)):
        model = tools.model(scene, problem)
        ref = explicit(model, problem, 5)
        rel = lambda a, b: abs(sxx(b)[0] / sxx(a)[0] - 1)
        for solver in ('cg', 'gmres'):
            table(problem, solver, model, ref, bar_cases, rel, 'sigma_xx error vs explicit')
        # The stress against the uniaxial law (the seed's eq. 3.1.1 and its bilinear
        # counterpart): the scene (plane stress, frictionless ends, to the seed's last frame),
        # the same at the nominal end time, with both ends sticking, and in plane strain.
        # Particles (mean, min, max) and the mesh (nodal).
        imp = results['runs'][f'{problem}_gmres_100a']
        t_end = 10.34 if problem == 'elastic_bar' else 24.34
        b = {f'scene, t = {t_end:g}': {'law': uniaxial_law(problem, t_end), 'explicit': sxx(ref),
                                       'implicit_100a': sxx(imp), 'explicit_nodes': nodal_sxx(tools, ref),
                                       'implicit_100a_nodes': nodal_sxx(tools, imp)}}
        implicit_sets = ['solver.type=implicit', f'solver.implicit.newton_tolerance={TOL[problem][0]}',
                         f'solver.implicit.linear_tolerance={TOL[problem][1]}']
        sticking = tools.model(scene, problem + '_sticking', ['bodies.puller.slip=none', 'boundary.x_max=fixed'])
        strain = tools.model(scene, problem + '_plane_strain', ['scene.geometry=plane-strain'])
        for case, m, t in ((f'scene, t = {t_nominal:g}', model, t_nominal),
                           (f'both ends sticking, t = {t_nominal:g}', sticking, t_nominal),
                           (f'plane strain, t = {t_end:g}', strain, t_end)):
            name = f'{problem}_{case.split(",")[0].replace(" ", "_")}_t{t:g}'
            ex = tools.simulate(m, name + '_explicit', [f'solver.end_time={t}'])
            im = tools.simulate(m, name + '_implicit', [f'solver.end_time={t}'] + implicit_sets)
            b[case] = {'law': uniaxial_law(problem, t), 'explicit': sxx(ex), 'implicit_100a': sxx(im),
                       'explicit_nodes': nodal_sxx(tools, ex), 'implicit_100a_nodes': nodal_sxx(tools, im)}
        results['bars'][problem] = b

    # Disks -----------------------------------------------------------------------------------
    model = tools.model('disks.toml', 'disks')
    ref = explicit(model, 'disks', 3)
    e0, e1 = energy(ref)

    def dissipation_error(a, b):
        ea, eb = energy(a), energy(b)
        return abs(eb[1] - ea[1]) / ea[0]
    table('disks', 'cg', model, ref, [(1, 'a'), (10, 'a'), (100, 'a'), (100, 'c')], dissipation_error,
          'energy lost vs explicit (of E0)')
    d = {'explicit': 1 - e1 / e0}
    for m in ('1a', '10a', '100a', '100c'):
        r = results['runs'].get(f'disks_cg_{m}')
        if r:
            a, b = energy(r)
            d[m] = 1 - b / a
    results['disks'] = d

    # Upsetting -------------------------------------------------------------------------------
    model = tools.model('upsetting.toml', 'upsetting')
    ref = explicit(model, 'upsetting', 2)
    mults = [100, 1000, 10000] if quick else [1, 10, 100, 1000, 10000]
    table('upsetting', 'gmres', model, ref, [(m, 'k') for m in mults] + [(m, 'kt') for m in mults if m >= 10],
          lambda a, b: load_error(a, b)[0], 'load rms error vs explicit')
    u = {'explicit': {'final_load_kN': binned_load(ref)[max(binned_load(ref))], 'r_max_mm': r_max_mm(ref)}}
    for m in mults:
        r = results['runs'].get(f'upsetting_gmres_{m}k')
        if r:
            rms, final = load_error(ref, r)
            u[f'{m}x'] = {'final_load_kN': final, 'r_max_mm': r_max_mm(r), 'load_rms': rms}
    # Meshes halved twice at the coarse mesh's 1000x step (85.1 us), as the seed (Fig. 12b); the
    # Newton tolerance scaled with 1/h^2 to keep the relative force imbalance (the residual's
    # norm grows as 1/h^2 at equal imbalance: 1/h per node, 1/h from the node count).
    dt = 1000 * ref['explicit_dt']
    meshes = [('1', 0.1)] + [('0.5', 0.4)] + ([] if quick else [('0.25', 1.6)])
    for cell, tol in meshes:
        name = f'upsetting_mesh_{cell}'
        m_model = model if cell == '1' else tools.model('upsetting.toml', name, [f'grid.cell_size={cell} mm'])
        r = tools.simulate(m_model, name, ['solver.type=implicit', f'solver.dt_max={dt}',
                                           'solver.implicit.dt_initial_multiple=1e9',
                                           'solver.implicit.dt_target_multiple=1e9',
                                           f'solver.implicit.newton_tolerance={tol}',
                                           'solver.implicit.linear_tolerance=1e-2'])
        if r['status'] == 0:
            bl = binned_load(r)
            u[f'mesh_{cell}mm'] = {'final_load_kN': bl[max(bl)], 'r_max_mm': r_max_mm(r), 'steps': r['steps'],
                                   'newton': r['newton'], 'krylov': r['krylov'], 'evals': r['evals'],
                                   'wall': r['wall']}
            results.setdefault('runs', {})[name] = r
    results['upsetting'] = u

    # Options: forcing x preconditioner, residual evaluations --------------------------------
    md.append('### Options: forcing terms and preconditioner (residual evaluations, wall s; '
              'initial guess: the default of the formulation)')
    md.append('')
    md.append('| problem | solver | multiple | fixed, none | fixed, diagonal | fixed, tangent | EW, none | '
              'EW, diagonal | EW, tangent |')
    md.append('|---|---|---|---|---|---|---|---|---|')
    option_cases = [('elastic_bar', 'gmres', 100), ('elastic_bar', 'cg', 100), ('plastic_bar', 'gmres', 100),
                    ('plastic_bar', 'cg', 100), ('disks', 'cg', 10), ('disks', 'cg', 100),
                    ('upsetting', 'gmres', 100), ('upsetting', 'gmres', 1000), ('upsetting', 'gmres', 10000)]

    def option_run(problem, solver, mult, options):
        """One option case with the study's tolerances and steps; `options` maps keys of
        [solver.implicit] to values. Returns the table cell and records the run."""
        newton, linear = TOL[problem]
        initial = mult if problem == 'upsetting' else 1
        sets = ['solver.type=implicit', f'solver.implicit.formulation={"velocity" if solver == "cg" else "momentum"}',
                f'solver.implicit.newton_tolerance={newton}', f'solver.implicit.linear_tolerance={linear}',
                f'solver.implicit.dt_initial_multiple={initial}', f'solver.implicit.dt_target_multiple={mult}']
        sets += [f'solver.implicit.{k}={v}' for k, v in options.items()]
        r = tools.simulate(os.path.join(OUT, problem + '.model'),
                           f'opt_{problem}_{solver}_{mult}_' + '_'.join(options.values()), sets,
                           repeat=3 if problem != 'upsetting' or mult >= 1000 else 1)
        results['options'].append({'problem': problem, 'solver': solver, 'multiple': mult, **options,
                                   'evals': r.get('evals'), 'wall': r.get('wall')})
        return f'{int(r["evals"])}, {fmt(r["wall"], 3)}' if r['status'] == 0 else 'failed'

    for problem, solver, mult in option_cases:
        cells = [option_run(problem, solver, mult, {'forcing': forcing, 'preconditioner': pc})
                 for forcing in ('fixed', 'eisenstat-walker') for pc in ('none', 'diagonal', 'tangent')]
        md.append(f'| {problem} | {solver} | {mult} | ' + ' | '.join(cells) + ' |')
    md.append('')

    # Options: Newton's initial guess, with the default forcing and preconditioner ------------
    md.append('### Options: Newton\'s initial guess (residual evaluations, wall s; default forcing and '
              'preconditioner)')
    md.append('')
    md.append('| problem | solver | multiple | particles (v^k) | previous (v^L of the last step) |')
    md.append('|---|---|---|---|---|')
    guess_cases = [('elastic_bar', 'cg', 10), ('plastic_bar', 'cg', 10), ('plastic_bar', 'gmres', 10)] + option_cases
    for problem, solver, mult in guess_cases:
        cells = [option_run(problem, solver, mult, {'initial_guess': guess}) for guess in ('particles', 'previous')]
        md.append(f'| {problem} | {solver} | {mult} | ' + ' | '.join(cells) + ' |')
    md.append('')

    # Bars, disks, upsetting summaries --------------------------------------------------------
    md.append('### Bar stresses: sigma_xx mean, min, max over the bar\'s particles, and over the '
              'interior nodes (mesh) where the seed graphs it')
    md.append('')
    md.append('| problem | case | uniaxial law | explicit, particles | explicit, mesh | implicit (100x), particles '
              '| implicit (100x), mesh |')
    md.append('|---|---|---|---|---|---|---|')
    for problem, b in results['bars'].items():
        for case, v in b.items():
            md.append(f'| {problem} | {case} | {fmt(v["law"], 5)} | ' + ' | '.join(
                ', '.join(fmt(x, 5) for x in v[k])
                for k in ('explicit', 'explicit_nodes', 'implicit_100a', 'implicit_100a_nodes')) + ' |')
    md.append('')
    md.append('### Colliding disks: energy lost by t = 150 (of the initial kinetic energy)')
    md.append('')
    md.append('| explicit | ' + ' | '.join(k for k in results['disks'] if k != 'explicit') + ' |')
    md.append('|---|' + '---|' * (len(results['disks']) - 1))
    md.append(' | '.join([fmt(results['disks']['explicit'])] + [fmt(v) for k, v in results['disks'].items()
                                                                   if k != 'explicit']).join(['| ', ' |']))
    md.append('')
    md.append('### Upsetting: final load (mean over the last 0.5 mm of platen travel) and largest radius')
    md.append('')
    md.append('| case | final load (kN) | r_max (mm, particle centres) | load rms vs explicit |')
    md.append('|---|---|---|---|')
    for case, v in results['upsetting'].items():
        md.append(f'| {case} | {fmt(v["final_load_kN"])} | {fmt(v["r_max_mm"])} | {fmt(v.get("load_rms"))} |')
    md.append('')
    with open(os.path.join(OUT, 'tables.md'), 'w') as f:
        f.write('\n'.join(md) + '\n')
    slim = {k: v for k, v in results.items() if k != 'runs'}
    with open(os.path.join(OUT, 'summary.json'), 'w') as f:
        json.dump(slim, f, indent=1, default=str)
    plots(results)
    print('\n'.join(md))


# ------------------------------------------------------------------------------------------
# Plots (gnuplot, PNG)

def gnuplot(script):
    r = subprocess.run(['gnuplot'], input=script, capture_output=True, text=True, cwd=OUT)
    if r.returncode != 0:
        print('gnuplot:', r.stderr, file=sys.stderr)


def plots(results):
    runs = results['runs']
    # Disks: energies of the explicit run and the implicit runs, one panel each.
    panels = [('disks_explicit', 'explicit')] + [(f'disks_cg_{m}a', f'implicit, {m}x explicit dt')
                                                  for m in (1, 10, 100)]
    s = ['set terminal pngcairo noenhanced size 1400,1000 font ",11"', "set output 'disks_energy.png'",
         'set multiplot layout 2,2 title "V7 colliding disks: kinetic, strain and total energy (J per m)"',
         'set datafile separator ","', 'set datafile columnheaders', 'set key top right', 'set xlabel "t"', 'set ylabel "energy"',
         'set xrange [0:150]', 'set yrange [0:*]']
    for name, title in panels:
        if name not in runs and name != 'disks_explicit':
            continue
        f = f'{name}_history.csv'
        s.append(f'set title "{title}"')
        s.append(f"plot '{f}' using (column('time')):(column('kinetic')) with lines dt 2 lw 2 title 'kinetic', "
                 f"'' using (column('time')):(column('internal')) with lines dt 3 lw 2 title 'strain', "
                 f"'' using (column('time')):(column('total')) with lines lw 2 title 'total'")
    s.append('unset multiplot')
    gnuplot('\n'.join(s) + '\n')

    # Upsetting: load-deflection, time steps (left) and meshes (right).
    s = ['set terminal pngcairo noenhanced size 1400,600 font ",11"', "set output 'upsetting_load.png'",
         'set multiplot layout 1,2 title "V7 upsetting: platen load against platen travel"',
         'set datafile separator ","', 'set datafile columnheaders', 'set key top left', 'set xlabel "platen travel (mm)"',
         'set ylabel "load (kN)"', 'set xrange [0:10]', 'set yrange [0:*]',
         'set title "coarse mesh (1 mm): explicit and implicit at dt multiples"']
    curves = ["'upsetting_explicit_history.csv' using (column('time')*1e3):(column('force_platen_y')/1e3) "
              "with lines lw 1 lc rgb 'gray' title 'explicit'"]
    for m in (10, 100, 1000, 10000):
        if f'upsetting_gmres_{m}k' in runs:
            curves.append(f"'upsetting_gmres_{m}k_history.csv' using (column('time')*1e3):(column('force_platen_y')/1e3) "
                          f"with linespoints pt 7 ps 0.4 title 'implicit {m}x'")
    s.append('plot ' + ', '.join(curves))
    s.append('set title "implicit at 85 us (1000x the coarse explicit step), meshes halved twice"')
    curves = []
    for cell in ('1', '0.5', '0.25'):
        if f'upsetting_mesh_{cell}' in runs:
            curves.append(f"'upsetting_mesh_{cell}_history.csv' using (column('time')*1e3):(column('force_platen_y')/1e3) "
                          f"with linespoints pt 7 ps 0.4 title '{cell} mm'")
    s.append("set yrange [0:1200]")
    s.append("set key bottom right")
    s.append("set arrow from 9.3,800 to 10,800 nohead lw 3 lc rgb 'black'")
    s.append("set label 'seed, refined: 800 kN' at 6.3,760")
    s.append("set arrow from 9.3,1050 to 10,1050 nohead lw 3 lc rgb 'red'")
    s.append("set label 'seed, coarse: 1050 kN' at 6.3,1090 tc rgb 'red'")
    s.append('plot ' + ', '.join(curves))
    s.append('unset multiplot')
    gnuplot('\n'.join(s) + '\n')

    # Cost ratio and error against the dt multiple.
    series = []
    for key, t in results['tables'].items():
        pts = [(r['multiple'], r['wall_ratio'], r['ops_ratio'], r['error'], r.get('seed'))
               for r in t['rows'] if r.get('status', 0) == 0 and r['ramp'] in ('a', 'k')]
        if not pts:
            continue
        fname = key.replace('/', '_') + '_cost.dat'
        with open(os.path.join(OUT, fname), 'w') as f:
            f.write('# multiple wall_ratio ops_ratio error seed\n')
            for p in pts:
                f.write(' '.join(str(x if x is not None else 'NaN') for x in p) + '\n')
        series.append((key, fname))
    s = ['set terminal pngcairo noenhanced size 1400,600 font ",11"', "set output 'cost_error.png'",
         'set multiplot layout 1,2 title "V7: cost and error of the implicit solver against its time step"',
         'set logscale xy', 'set format y "%g"', 'set xlabel "dt / explicit dt"', 'set grid', 'set key bottom left',
         'set title "cost ratio to the explicit run (wall time; open: residual evaluations; crosses: seed)"',
         'set ylabel "cost ratio"']
    curves = []
    for i, (key, fname) in enumerate(series):
        c = i + 1
        curves.append(f"'{fname}' using 1:2 with linespoints lc {c} pt 7 lw 2 title '{key}'")
        curves.append(f"'{fname}' using 1:3 with linespoints lc {c} pt 6 dt 2 notitle")
        curves.append(f"'{fname}' using 1:5 with points lc {c} pt 2 ps 1.5 notitle")
    s.append('plot ' + ', '.join(curves) + ', 1 with lines lc rgb "black" dt 3 notitle')
    s.append('set title "error against the explicit run (bars: sigma_xx; disks: energy; upsetting: load rms)"')
    s.append('set ylabel "relative error"')
    curves = [f"'{fname}' using 1:($4>0?$4:1e-9) with linespoints lc {i + 1} pt 7 lw 2 title '{key}'"
              for i, (key, fname) in enumerate(series)]
    s.append('plot ' + ', '.join(curves))
    s.append('unset multiplot')
    gnuplot('\n'.join(s) + '\n')


if __name__ == '__main__':
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    study(Tools(os.path.abspath(sys.argv[1])), '--quick' in sys.argv[2:])
