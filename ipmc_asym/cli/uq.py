"""``ipmc-asym uq``: uncertainty (quantiles) and Sobol' sensitivity of a scene's outputs."""

from __future__ import annotations

import sys

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import compiled_fidelities
from ipmc_asym.base.settings import MAX_SAMPLES_CEILING, MAX_STORE_SAMPLES_CEILING
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_electrode_options,
    add_material_options,
    add_output_option,
    add_size_option,
    first_run_notice,
    fmt_num,
    print_citations,
    scene_with_material,
    seed_type,
)
from ipmc_asym.io.datasets import uq_dataset, write_netcdf
from ipmc_asym.io.fileio import FIGURE_FORMATS, check_output_path
from ipmc_asym.model.electrode import beam_label
from ipmc_asym.parallel.executors import check_scheduler
from ipmc_asym.studies.scene_schema import load_scene
from ipmc_asym.studies.uq import SOBOL_BATCHES, STORE_SAMPLES, run_uq

#: model runs of one uq: a time cap (memory does not grow with the runs: the design is streamed
#: chunk by chunk; ~1e6 runs/s at leading in one process, so ~2 min here); settable with --max-samples
MAX_SAMPLES = 10**8
#: runs kept per sample for --out and --plot (~100 B each): a memory cap, settable with --max-store-samples
MAX_STORE_SAMPLES = 2 * 10**6
#: fewer runs give no usable 2.5 %/97.5 % quantile (a handful of samples beyond each) nor a
#: Sobol' index with a batch-means interval
MIN_SAMPLES = 100


def register(sub):
    p = sub.add_parser("uq", help=SUMMARIES["uq"],
                       description="Sample a scene's [uncertain] table (normal, lognormal, uniform, triangular), "
                                   "report quantiles 2.5/50/97.5 %, mean, sd and Sobol' first/total indices.")
    p.add_argument("scene", metavar="SCENE.toml", help="scene with an [uncertain] table (examples/uq_nominal.toml)")
    add_size_option(p, "--samples", default=10**5, maximum=MAX_SAMPLES, ceiling=MAX_SAMPLES_CEILING, minimum=MIN_SAMPLES,
                    help=f"model runs wanted (>= {MIN_SAMPLES}; rounded up to N(D+2), N a power of two; streamed: "
                         "memory does not grow with it, the cap bounds the time)")
    add_size_option(p, "--store-samples", default=STORE_SAMPLES, maximum=MAX_STORE_SAMPLES, ceiling=MAX_STORE_SAMPLES_CEILING, minimum=0,
                    help="runs kept per sample for --out and --plot: the first whole Saltelli groups of the design "
                         "(the statistics use every run)")
    p.add_argument("--fidelity", default=None, choices=list(compiled_fidelities()),
                   help="force a fidelity (default: per sample, cheapest meeting the scene's tolerance)")
    p.add_argument("--seed", type=seed_type, default=0,
                   help="seed of the scrambled Sobol' sequence (integer >= 0, default 0; stored in the NetCDF)")
    p.add_argument("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
                   help="run the chunks on dask.distributed (default: in this process)")
    add_output_option(p, "--out", formats=(".nc",), default=None, metavar="F.nc",
                   help="NetCDF file (.nc) of the statistics, the indices and the first --store-samples runs")
    add_output_option(p, "--plot", formats=FIGURE_FORMATS, default=None, metavar="F.png",
                   help=f"histograms of the outputs ({', '.join(FIGURE_FORMATS)})")
    p.add_argument("--keep-invalid", action="store_true",
                   help="keep the samples outside a model assumption (past a quarter turn, above the strain limit, "
                        "beyond the validated voltage, not slender) in the statistics; by default they are counted "
                        "and left out (their check_* variables are in the NetCDF either way)")
    p.add_argument("--spread", action="store_true",
                   help="also run the study with the other two permittivity models and report the range of each "
                        "output's mean, sd and quantiles over the three (JSON model_spread; the model-form spread "
                        "beside the sampling error; three times the work)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_material_options(p)
    add_electrode_options(p)
    p.set_defaults(material=None)  # default: the scene's [material]


def run(args) -> int:
    if args.out:
        check_output_path(args.out, "file", "--out", formats=(".nc",))
    if args.plot:
        check_output_path(args.plot, "file", "--plot", formats=FIGURE_FORMATS)
    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    scene = scene_with_material(args.scene, args)
    if not isinstance(scene, dict):  # read here, before the notice: a refused file is one line
        scene = load_scene(scene)
    first_run_notice()
    res = run_uq(scene, args.samples, seed=args.seed, fidelity=args.fidelity,
                 scheduler=args.scheduler, keep_invalid=args.keep_invalid, store_samples=args.store_samples,
                 spread=args.spread)
    if args.cite and res.material is not None:
        print_citations(res.material, json_mode=args.json)
    if res.n_outside:
        how = "kept in the statistics (--keep-invalid)" if res.keep_invalid else \
            f"left out of the statistics ({res.n_used} samples used; Sobol' indices on {res.n_sobol} of {res.base_n} " \
            "base points; --keep-invalid keeps them)"
        sys.stderr.write(f"uq: {res.n_outside} of {res.n_samples} samples outside a model assumption, {how}\n")
        for w in res.warnings:
            sys.stderr.write(f"uq: warning: {w}\n")
    if res.base_n < 4 * SOBOL_BATCHES:
        sys.stderr.write(f"uq: warning: N = {res.base_n} base points (< {4 * SOBOL_BATCHES}): the Sobol' indices "
                         f"and their intervals are rough; use --samples {4 * SOBOL_BATCHES * (len(res.inputs) + 2)} "
                         f"or more\n")
    if args.out:
        ds = uq_dataset(res)
        ds.attrs["seed"] = int(args.seed)  # the run is reproducible from the file alone
        eng = write_netcdf(ds, args.out)
        kept = f"the first {res.n_stored} of {res.n_samples}" if res.n_stored < res.n_samples else f"{res.n_samples}"
        sys.stderr.write(f"uq: {kept} samples -> {args.out} (NetCDF, engine {eng}; statistics over all "
                         f"{res.n_samples})\n")
    if args.plot:
        from ipmc_asym.plotting.uq import plot_uq  # deferred: matplotlib (start-up)

        plot_uq(res, args.plot)
    if args.json:
        print(dumps(res.as_dict(), indent=2))
        return 0
    fid = ", ".join(f"{k}: {v}" for k, v in res.fidelity.items() if v)
    print(f"uq of scene {res.scene!r} [{res.model}]: {res.n_samples} runs (N = {res.base_n}), {res.seconds:.3g} s; "
          f"fidelity per sample: {fid}; thickness is the TOTAL thickness 2e")
    if res.material is not None and res.material.electrode.present:
        print(f"beam: {beam_label(res.material.electrode)}")
    print(f"{'output':15s} {'unit':5s} {'mean':>11s} {'sd':>10s} {'2.5%':>11s} {'50%':>11s} {'97.5%':>11s}")
    for o, s in res.summary.items():
        print(f"{o:15s} {s['unit']:5s} {s['mean']:11.5g} {s['sd']:10.3g} {s['q2.5']:11.5g} {s['q50']:11.5g} "
              f"{s['q97.5']:11.5g}")
    rank = max(s["quantile_rank_error"] for s in res.summary.values())
    if rank > 0:
        print(f"quantiles from a sketch: rank error <= {rank:.2g} (each quantile's guaranteed interval in --json)")
    if res.model_spread is not None:
        sp = res.model_spread
        print(f"model-form spread ({sp['over']}): min .. max of each statistic")
        for o, q in sp["quantities"].items():
            print(f"  {o}: " + "; ".join(f"{st} {fmt_num(q[st]['min'], '.4g')} .. {fmt_num(q[st]['max'], '.4g')}"
                                          for st in ("mean", "q2.5", "q97.5")))
        for m, why in sp["refused"].items():
            print(f"  {m}: refused: {why}")
    print("Sobol' indices (first S1 / total ST, ± 95 % half-width):")
    for o, sob in res.sobol.items():
        if sob is None:
            print(f"  {o}: constant output, no indices")
            continue
        print(f"  {o}: " + "; ".join(f"{k} S1={fmt_num(v['S1'], '.3f')}±{fmt_num(v['S1_conf'], '.1g')} "
                                      f"ST={fmt_num(v['ST'], '.3f')}±{fmt_num(v['ST_conf'], '.1g')}"
                                      for k, v in sob.items()))
    if args.plot:
        print(f"figure: {args.plot}")
    return 0
