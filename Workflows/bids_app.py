"""dynsub-bids: the cohort workflow as a BIDS App.

    dynsub-bids BIDS_DIR OUTPUT_DIR participant|group [--participant-label L ...] [--session-label L ...]

The interface is the BIDS Apps one (Gorgolewski et al., 2017): the
participant level segments the chosen participants' images (any number of
such runs may share OUTPUT_DIR at once); the group level writes the group
table and the QC page from the segmentations already in OUTPUT_DIR and
starts none. Snakemake (Workflows/Snakefile) runs the jobs underneath, so a
rerun redoes only what is missing or changed, and `--profile` sends the jobs
to a cluster. Snakemake's own bookkeeping and the cluster's logs go to
OUTPUT_DIR/work, which .bidsignore lists.

Exit codes: 0 done, 1 a job or the workflow failed, 2 a usage error.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys

import dynsub_bids as bids


def _parser(version):
    parser = argparse.ArgumentParser(
        prog="dynsub-bids", allow_abbrev=False,
        description="Segment structures of a BIDS dataset's T1w images with DynSub (a BIDS App).",
        epilog="Landmarks: BIDS_DIR/derivatives/landmarks/sub-<label>/[ses-<label>/]anat/"
               "sub-<label>[_ses-<label>]_desc-<structure>_landmarks.{mrk.json,fcsv,csv}; seed clicks: "
               "BIDS_DIR/derivatives/seeds.tsv; references: BIDS_DIR/derivatives/reference "
               "(Documentation/Ecosystem.md, 'Cohorts').")
    parser.add_argument("bids_dir", help="the BIDS dataset")
    parser.add_argument("output_dir", help="the derivative dataset written, e.g. BIDS_DIR/derivatives/dynsub")
    parser.add_argument("analysis_level", choices=("participant", "group"),
                        help="participant: segment; group: the table and the QC page of what is segmented")
    parser.add_argument("--participant-label", "--participant_label", dest="participant_label", nargs="+",
                        default=[], metavar="LABEL", help="only these participants (with or without sub-)")
    parser.add_argument("--session-label", "--session_label", dest="session_label", nargs="+", default=[],
                        metavar="LABEL", help="only these sessions (with or without ses-)")
    parser.add_argument("--landmarks", metavar="DIR", help="landmark files (default BIDS_DIR/derivatives/landmarks)")
    parser.add_argument("--seeds", metavar="TSV", help="seed clicks (default BIDS_DIR/derivatives/seeds.tsv)")
    parser.add_argument("--reference", metavar="DIR",
                        help="expert labelmaps for Dice (default BIDS_DIR/derivatives/reference)")
    parser.add_argument("--segment-args", default="", metavar="ARGS",
                        help='further `dynsub segment` options, e.g. "--max-level 2"')
    parser.add_argument("--cores", type=int, default=os.cpu_count() or 1, metavar="N",
                        help="jobs at once on this machine (default: every core)")
    parser.add_argument("--profile", metavar="DIR",
                        help="a Snakemake profile, e.g. Workflows/profiles/slurm to submit each job with sbatch")
    parser.add_argument("--work-dir", metavar="DIR", help="Snakemake's bookkeeping (default OUTPUT_DIR/work)")
    parser.add_argument("--dry-run", action="store_true", help="list the jobs without running them")
    parser.add_argument("--unlock", action="store_true",
                        help="remove the lock a killed run left in the work directory, and stop")
    parser.add_argument("--version", action="version", version=f"%(prog)s (DynSub) {version}")
    return parser


def _version(dynsub):
    """dynsub's version, or None when it cannot be run."""
    try:
        return subprocess.run([dynsub, "--version"], capture_output=True, text=True, check=True).stdout.split()[-1]
    except (OSError, IndexError, subprocess.CalledProcessError):
        return None


def _description_problem(path):
    """What makes a dataset's description invalid BIDS, or None: BIDS asks
    for a JSON object with Name and BIDSVersion as text. Found here, before
    any job starts, rather than by the validator or another BIDS tool after
    every subject is segmented."""
    try:
        with open(path, encoding="utf-8-sig") as file:
            text = file.read()
    except (OSError, UnicodeDecodeError) as error:
        return f"cannot be read ({error.strerror if isinstance(error, OSError) else error})"
    try:
        description = json.loads(text)
    except ValueError as error:
        return f"not readable as JSON ({error})"
    if not isinstance(description, dict):
        return "not a JSON object"
    for key in ("Name", "BIDSVersion"):
        if key not in description:
            return f"no {key} (BIDS requires Name and BIDSVersion)"
        if not isinstance(description[key], str):
            return f"{key} is {json.dumps(description[key])}, not text (BIDS requires a string)"
    return None


def main(argv, snakefile, dynsub):
    """Runs the BIDS App; snakefile and dynsub are where the build put them."""
    version = _version(dynsub)
    parser = _parser(version or "unknown")
    args = parser.parse_args(argv)
    if version is None:
        print(f"dynsub-bids: error: {dynsub}: cannot run dynsub; build it (./run build)", file=sys.stderr)
        return 1
    try:
        participants, sessions = bids.labels(args.participant_label), bids.labels(args.session_label)
    except bids.CohortError as error:
        parser.error(str(error))
    if args.cores < 1:
        parser.error(f"--cores {args.cores}: at least 1")
    if not os.path.isdir(args.bids_dir):
        parser.error(f"{args.bids_dir}: no such BIDS directory")
    description = os.path.join(args.bids_dir, "dataset_description.json")
    if not os.path.isfile(description):
        parser.error(f"{args.bids_dir}: not a BIDS dataset (no dataset_description.json)")
    problem = _description_problem(description)
    if problem:
        parser.error(f"{description}: {problem}")
    if args.profile and not os.path.isfile(os.path.join(args.profile, "config.yaml")):
        parser.error(f"--profile {args.profile}: not a Snakemake profile (no config.yaml in it)")
    bids_dir, out = os.path.abspath(args.bids_dir), os.path.abspath(args.output_dir)
    # Compared as the files they are: through a symbolic link the output would
    # overwrite the dataset's own description and .bidsignore.
    if os.path.realpath(out) == os.path.realpath(bids_dir):
        parser.error(f"{args.output_dir}: the output directory must not be the BIDS dataset itself")
    # Inside the dataset, outputs outside the folders BIDS leaves to the user
    # (derivatives/, sourcedata/, code/, hidden ones) make it invalid BIDS.
    inside = os.path.relpath(os.path.realpath(out), os.path.realpath(bids_dir))
    top = inside.split(os.sep)[0]
    if top != os.pardir and top not in ("derivatives", "sourcedata", "code") and not top.startswith("."):
        suggested = os.path.join(args.bids_dir, "derivatives", "dynsub")
        parser.error(f"{args.output_dir}: inside the BIDS dataset but not in its derivatives folder, where the "
                     f"outputs would make the dataset invalid; use {suggested}")
    work = os.path.abspath(args.work_dir or os.path.join(out, "work"))
    # Snakemake 7 starts each job with an unquoted `cd WORK`.
    if shlex.quote(work) != work:
        parser.error(f"{work}: Snakemake cannot run jobs in a work directory whose path has a space or another "
                     "character a shell would read; give --work-dir a path of letters, digits and ./-_ only")

    # Values go to Snakemake as JSON, which its YAML reading keeps as given:
    # a label "01" stays a string, and a list stays a list.
    config = {"bids": bids_dir, "out": out, "dynsub": dynsub, "level": args.analysis_level,
              "participant_label": participants, "session_label": sessions, "segment_args": args.segment_args}
    for key in ("landmarks", "seeds", "reference"):
        if getattr(args, key):
            config[key] = os.path.abspath(getattr(args, key))
    # The dataset is read here first, so that a label that selects nothing or
    # a misnamed file is refused before anything is written.
    try:
        everything = bids.dataset_jobs(config)
        jobs = bids.select_jobs(everything, participants, sessions)
    except (bids.CohortError, OSError) as error:
        print(f"dynsub-bids: error: {error}", file=sys.stderr)
        return 1
    if args.analysis_level == "participant" and not args.unlock:
        for warning in bids.uncovered_warnings(config, jobs):
            print(f"dynsub-bids: warning: {warning}", file=sys.stderr)
    if args.analysis_level == "group" and not args.unlock and not bids.written_reports(jobs, out):
        print(f"dynsub-bids: error: {out}: no segmentation written yet; run the participant level first",
              file=sys.stderr)
        return 1
    if args.analysis_level == "group" and not args.unlock:
        for path in bids.unclaimed_labelmaps(everything, out):
            print(f"dynsub-bids: warning: {path}: left by an earlier run; the dataset no longer names its subject, "
                  "image or structure, so the group table leaves it out (delete it and its files if it is stale)",
                  file=sys.stderr)

    if not args.dry_run and not args.unlock:
        os.makedirs(work, exist_ok=True)
        os.makedirs(out, exist_ok=True)
        bids.write_dataset_description(os.path.join(out, "dataset_description.json"), version, bids_dir)
        bids.write_bidsignore(os.path.join(out, ".bidsignore"))

    command = ["snakemake", "-s", snakefile, "--directory", work, "--keep-going", "--rerun-incomplete",
               "--config", *(f"{key}={json.dumps(value)}" for key, value in config.items())]
    command += ["--profile", os.path.abspath(args.profile)] if args.profile else ["--cores", str(args.cores)]
    if args.dry_run:
        command.append("--dry-run")
    if args.unlock:
        command.append("--unlock")
    command.append(args.analysis_level)
    try:
        snakemake = subprocess.Popen(command)
    except OSError as error:
        print(f"dynsub-bids: error: cannot run snakemake ({error}); install Debian's snakemake", file=sys.stderr)
        return 1
    # Ctrl-C reaches Snakemake too (one process group): it is waited for, so
    # that it stops its jobs and removes its lock, rather than killed.
    interrupted = False
    while True:
        try:
            status = snakemake.wait()
            break
        except KeyboardInterrupt:
            interrupted = True
    if interrupted:
        print("dynsub-bids: interrupted; run the same command again to finish", file=sys.stderr)
        return 130
    return 0 if status == 0 else 1
