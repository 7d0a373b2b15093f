"""The BIDS side of the DynSub cohort workflow (Snakefile): which jobs a
dataset holds, what each job writes and under which BIDS derivative names,
and the group table.

A job is one `dynsub segment` run on one T1w image: every structure it has
landmarks or a seed click for, segmented together so that they do not
overlap.

Naming (BIDS 1.9 derivatives, "imaging data types: segmentations"), beside
the image's own path. A job of one structure names its labelmap by it:

    sub-<label>[/ses-<label>]/anat/sub-<label>[_ses-<label>][entities]_space-orig_desc-<structure>_dseg.nii.gz
    ..._dseg.tsv     the lookup table (index, name, color)
    ..._dseg.json    sidecar: Sources, SpatialReference, the structures' files
    ..._report.json  dynsub segment's report

and a job of several structures has one labelmap for them all, with their
run's report (the overlaps, each structure's share):

    .../anat/sub-<label>[_ses-<label>][entities]_space-orig_dseg.nii.gz, .tsv, .json, _report.json

Each structure keeps its own files either way:

    .../anat/..._space-orig_desc-<structure>_surface.vtp   the fitted limit surface (LPS mm)
    .../anat/..._space-orig_desc-<structure>_convergence.csv
    .../anat/..._space-orig_desc-<structure>_report.json   its own segmentation's report
    sub-<label>[/ses-<label>]/figures/..._desc-<structure>_{slices,surface3d,convergence}.png

and the job's interactive view for the QC page is figures/..._[desc-<structure>_]view.js
(qc_view.py).

`space-orig` is the T1w's own grid; `desc-` carries the structure, so BIDS
labels (letters and digits only) are required of structure names. The T1w's
own entities (acq-, ce-, rec-, run-, echo-, part-) are carried through,
so two runs of a session are two jobs; a landmark file or seed
without them serves the session's one T1w. `.bidsignore` lists the files
the derivatives specification has no rule for.
"""
import csv
import glob
import json
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

import qc_view

LABEL = r"[A-Za-z0-9]+"
# The entities a raw T1w's name may carry between ses- and the suffix, in
# BIDS order; they are carried into the derivatives' names, so that two runs
# of one subject are two jobs. chunk- is left out: BIDS orders it after
# space-, which the outputs' names add after these.
ENTITIES = ("acq", "ce", "rec", "run", "echo", "part")
ENTITY_PATTERN = "".join(rf"(?:_{e}-{LABEL})?" for e in ENTITIES)
T1W = re.compile(rf"^sub-(?P<sub>{LABEL})(?:_ses-(?P<ses>{LABEL}))?(?P<entities>{ENTITY_PATTERN})_T1w\.nii(?:\.gz)?$")
LANDMARKS = re.compile(rf"^sub-(?P<sub>{LABEL})(?:_ses-(?P<ses>{LABEL}))?(?P<entities>{ENTITY_PATTERN})"
                       rf"_desc-(?P<structure>{LABEL})_landmarks\.(?:mrk\.json|fcsv|csv)$")
FIGURES = ("slices", "surface3d", "convergence")
# The colour a structure alone gets in its dseg.tsv: the first of the
# palette `dynsub segment` gives several structures.
LABEL_COLOR = "#4e79a7"


class CohortError(Exception):
    """A dataset the workflow cannot run on; the message names the file."""


class Structure:
    """One structure of one T1w image, and what it starts from."""

    def __init__(self, subject, session, entities, name, t1w):
        self.subject, self.session, self.entities = subject, session, entities  # entities: "" or "_run-1", ...
        self.name, self.t1w = name, t1w
        self.landmarks = None          # a landmark file, and/or
        self.seed = None               # (x, y, z) LPS mm of one click inside
        self.reference = None          # an expert labelmap on the T1w's grid
        self.reference_labels = []     # the structure's values in it

    @property
    def dir(self):  # sub-01 or sub-01/ses-1
        return f"sub-{self.subject}" + (f"/ses-{self.session}" if self.session else "")

    @property
    def stem(self):  # sub-01, sub-01_ses-1, sub-01_ses-1_run-2, ...
        return f"sub-{self.subject}" + (f"_ses-{self.session}" if self.session else "") + self.entities

    @property
    def key(self):
        return (self.stem, self.name)


class Job:
    """One `dynsub segment` run: the structures of one T1w image, in
    dseg.tsv's order: those with landmarks first, then those from a seed
    click alone (the order in which `dynsub segment` pairs an --init per
    structure with the point lists)."""

    def __init__(self, structures):
        self.structures = structures
        first = structures[0]
        self.subject, self.session, self.entities, self.t1w = first.subject, first.session, first.entities, first.t1w
        self.dir, self.stem = first.dir, first.stem
        # The expert labelmap, when it names every structure of the job: a
        # run of several structures scores all of them or none.
        named = all(s.reference for s in structures)
        self.reference = first.reference if named else None
        self.reference_labels = [s.reference_labels for s in structures] if named else []

    @property
    def desc(self):  # the wildcard: "_desc-<structure>" for one structure, "" for several
        return f"_desc-{self.structures[0].name}" if len(self.structures) == 1 else ""

    @property
    def key(self):
        return (self.stem, self.desc)

    @property
    def name(self):  # its log's, its view's and its QC section's name
        return self.stem + self.desc

    @property
    def seeds(self):  # each structure's seed click, or None
        return [s.seed for s in self.structures]

    def inputs(self):
        files = {"t1w": self.t1w}
        for s in self.structures:
            if s.landmarks:
                files[f"landmarks_{s.name}"] = s.landmarks
        if self.reference:
            files["reference"] = self.reference
        return files


def output_paths(out, dir, stem, desc):
    """The declared outputs of one job (desc: its wildcard, Job.desc)."""
    base = f"{out}/{dir}/anat/{stem}_space-orig{desc}"
    return {"dseg": base + "_dseg.nii.gz", "lut": base + "_dseg.tsv", "sidecar": base + "_dseg.json",
            "report": base + "_report.json"}


def structure_paths(out, dir, stem, name):
    """A structure's own files; for a job of one structure its report is the job's."""
    base = f"{out}/{dir}/anat/{stem}_space-orig_desc-{name}"
    return {"surface": base + "_surface.vtp", "convergence": base + "_convergence.csv",
            "report": base + "_report.json"}


def job_paths(out, job):
    return output_paths(out, job.dir, job.stem, job.desc)


def log_path(out, dir, stem, desc):
    return f"{out}/logs/{dir}/{stem}{desc}.log"


def default_seeds(bids):
    path = f"{bids}/derivatives/seeds.tsv"
    return path if os.path.exists(path) else None


def figure_paths(out, dir, stem, name):
    """A structure's figures."""
    return {figure: f"{out}/{dir}/figures/{stem}_desc-{name}_{figure}.png" for figure in FIGURES}


def view_path(out, dir, stem, desc):
    """A job's interactive view."""
    return f"{out}/{dir}/figures/{stem}{desc}_view.js"


def _own_folder(subject, session):
    """Where a file of a subject and session lies, relative to its dataset's root."""
    return os.path.join(f"sub-{subject}", *([f"ses-{session}"] if session else []), "anat")


def _in_own_folder(path, root, subject, session):
    """Whether path lies in its subject's and session's folder under root
    (however root is spelt: a trailing slash, a relative path)."""
    return os.path.relpath(os.path.dirname(path), root) == _own_folder(subject, session)


def _relative(path, root):
    return os.path.relpath(os.path.abspath(path), os.path.abspath(root))


def _warn(message):
    print(f"DynSub: warning: {message}", file=sys.stderr)


def _read_names(table):
    """A dseg.tsv's structure names -> their index values."""
    names = {}
    with open(table, newline="") as f:
        for row in csv.DictReader(f, delimiter="\t"):
            names.setdefault(row["name"], []).append(int(row["index"]))
    return names


def find_images(bids, warn=_warn):
    """Every T1w image of the dataset, keyed by (subject, session, entities);
    one whose name has entities other than ENTITIES is skipped with a warning."""
    if not os.path.isdir(bids):
        raise CohortError(f"{bids}: no such BIDS directory")
    images = {}  # (subject, session, entities) -> path
    for path in sorted(glob.glob(f"{bids}/sub-*/anat/*_T1w.nii*") + glob.glob(f"{bids}/sub-*/ses-*/anat/*_T1w.nii*")):
        match = T1W.match(os.path.basename(path))
        if not match:
            warn(f"{path}: skipped (a T1w is named sub-<label>[_ses-<label>][_{'-<label>][_'.join(ENTITIES)}-<label>]"
                 "_T1w.nii[.gz], in that order, letters and digits in labels)")
            continue
        subject, session = match["sub"], match["ses"]
        if not _in_own_folder(path, bids, subject, session):
            raise CohortError(f"{path}: its name does not match its folder")
        key = (subject, session, match["entities"])
        if key in images:  # .nii beside .nii.gz
            raise CohortError(f"{path}: a second file for the same T1w (also {images[key]})")
        images[key] = path
    return images


def find_structures(bids, landmarks_dir, seeds_table, reference_dir, warn=_warn):
    """Every (image, structure) with landmarks or a seed, keyed by (stem, structure name).

    A T1w whose name has entities other than ENTITIES is skipped with a
    warning; so is a reference found for a structure its table does not
    name.
    """
    images = find_images(bids, warn)
    structures = {}

    def structure_for(subject, session, entities, name, source):
        """The structure of the T1w a landmark file or seed names; without entities, the one T1w of its
        session."""
        where = f"sub-{subject}" + (f" ses-{session}" if session else "")
        if (subject, session, entities) in images:
            path = images[(subject, session, entities)]
        else:
            candidates = sorted(k for k in images if k[:2] == (subject, session) and not entities)
            if not candidates:
                raise CohortError(f"{source}: no T1w image for {where}" + (f" with {entities[1:]}" if entities else ""))
            if len(candidates) > 1:
                raise CohortError(f"{source}: {where} has {len(candidates)} T1w images ("
                                  + ", ".join(os.path.basename(images[k]) for k in candidates)
                                  + "); name the one meant (e.g. sub-<label>_run-<label>_desc-...)")
            entities, path = candidates[0][2], images[candidates[0]]
        found = Structure(subject, session, entities, name, path)
        return structures.setdefault(found.key, found)

    if landmarks_dir and os.path.isdir(landmarks_dir):
        for path in sorted(glob.glob(f"{landmarks_dir}/sub-*/anat/*_landmarks.*") +
                           glob.glob(f"{landmarks_dir}/sub-*/ses-*/anat/*_landmarks.*")):
            match = LANDMARKS.match(os.path.basename(path))
            if not match:
                raise CohortError(f"{path}: not handled (expected sub-<label>[_ses-<label>][entities]_desc-<structure>"
                                  "_landmarks.mrk.json|.fcsv|.csv, letters and digits in labels)")
            # A file copied from another subject's folder and not renamed would serve the subject its name says.
            if not _in_own_folder(path, landmarks_dir, match["sub"], match["ses"]):
                raise CohortError(f"{path}: its name is for {_own_folder(match['sub'], match['ses'])}, not the folder "
                                  "it is in; rename it for its folder's subject and session, or move it")
            structure = structure_for(match["sub"], match["ses"], match["entities"], match["structure"], path)
            if structure.landmarks:
                raise CohortError(f"{path}: a second landmark file for {structure.stem} {structure.name} "
                                  f"(also {structure.landmarks})")
            structure.landmarks = path

    if seeds_table:
        with open(seeds_table, newline="", encoding="utf-8-sig") as f:  # Excel writes a byte order mark
            rows = list(csv.DictReader(f, delimiter="\t"))
        for line, row in enumerate(rows, start=2):
            where = f"{seeds_table}:{line}"
            try:
                subject = row["participant_id"].removeprefix("sub-")
                session = (row.get("session_id") or "n/a").removeprefix("ses-")
                session = None if session == "n/a" else session
                name = row["structure"]
                seed = tuple(float(row[c]) for c in ("x", "y", "z"))
            except (KeyError, TypeError, ValueError):
                raise CohortError(f"{where}: expected columns participant_id, [session_id,] structure, x, y, z "
                                  "(LPS mm)") from None
            if not re.fullmatch(LABEL, name) or not all(abs(v) < float("inf") for v in seed):
                raise CohortError(f"{where}: structure must be letters and digits, x y z finite numbers")
            structure = structure_for(subject, session, "", name, where)
            if structure.seed is not None:
                raise CohortError(f"{where}: a second seed for {structure.stem} {structure.name}")
            structure.seed = seed

    if reference_dir and os.path.isdir(reference_dir):
        dataset_table = f"{reference_dir}/dseg.tsv"
        for structure in structures.values():
            # The image's own reference, else its session's; its own table, else the dataset's.
            folder = f"{reference_dir}/{structure.dir}/anat"
            session_stem = structure.stem[: len(structure.stem) - len(structure.entities)]
            stems = [structure.stem] + ([session_stem] if structure.entities else [])
            path = next((f"{folder}/{s}_dseg.nii.gz" for s in stems if os.path.exists(f"{folder}/{s}_dseg.nii.gz")),
                        None)
            if not path:
                continue
            tables = [f"{folder}/{s}_dseg.tsv" for s in stems] + [dataset_table]
            table = next((t for t in tables if os.path.exists(t)), None)
            names = _read_names(table) if table else {}
            if structure.name in names:
                structure.reference, structure.reference_labels = path, names[structure.name]
            else:
                warn(f"{path}: a reference for {structure.stem}, not used for {structure.name}: "
                     + (f"{table} names no '{structure.name}'" if table else
                        f"no dseg.tsv names its labels (looked for {', '.join(tables)})"))
    return structures


def group_jobs(structures, warn=_warn):
    """The jobs of the structures (find_structures'), keyed by Job.key: one
    per T1w image, its structures segmented together (Job's order). A
    reference that names some of a job's structures but not all is warned
    of: the job is not scored."""
    together, jobs = {}, {}
    for key in sorted(structures, key=lambda key: (key[0], not structures[key].landmarks, key[1])):
        together.setdefault(structures[key].stem, []).append(structures[key])
    for group in together.values():
        job = Job(group)
        jobs[job.key] = job
        unscored = [s for s in group if s.reference]
        if not job.reference and unscored:
            warn(f"{unscored[0].reference}: not used for {', '.join(s.name for s in unscored)} either: a run of "
                 "several structures is scored when the reference names them all")
    return jobs


def labels(value):
    """A participant_label or session_label setting as a list of labels.

    It comes as a list (the BIDS App passes one) or as "01,02"; a "sub-" or
    "ses-" prefix is dropped, as BIDS Apps accept both spellings."""
    if value is None or value == "":
        return []
    items = value if isinstance(value, (list, tuple)) else str(value).split(",")
    result = []
    for item in items:
        label = str(item).strip().removeprefix("sub-").removeprefix("ses-")
        if not re.fullmatch(LABEL, label):
            raise CohortError(f"'{item}': a label is letters and digits (sub-<label>, ses-<label>)")
        result.append(label)
    return result


def is_chosen(subject, session, participants, sessions):
    """Whether an image of this subject and session is among the given
    participants and sessions (all where a list is empty)."""
    return (not participants or subject in participants) and (not sessions or session in sessions)


def select_jobs(jobs, participants, sessions):
    """The jobs of the given participants and sessions (all where a list is
    empty). A label that selects nothing is an error: it is a typing slip more
    often than an intended no-op."""
    chosen = {key: job for key, job in jobs.items() if is_chosen(job.subject, job.session, participants, sessions)}
    for label in participants:
        if not any(job.subject == label for job in chosen.values()):
            raise CohortError(f"sub-{label}: no T1w image with landmarks or a seed"
                              + (f" in sessions {', '.join(sessions)}" if sessions else ""))
    for label in sessions:
        if not any(job.session == label for job in chosen.values()):
            raise CohortError(f"ses-{label}: no T1w image with landmarks or a seed")
    return chosen


def _sources(config):
    """A workflow configuration's dataset and where its landmarks, seeds and
    references are (the Snakefile's --config and the BIDS App's settings),
    with the same defaults for both."""
    root = os.path.abspath(str(config["bids"]))
    return (root, str(config.get("landmarks", f"{root}/derivatives/landmarks")),
            config.get("seeds", default_seeds(root)), str(config.get("reference", f"{root}/derivatives/reference")))


def dataset_jobs(config):
    """Every job of a workflow configuration's dataset, whichever
    participants and sessions it chooses."""
    root, landmarks, seeds, reference = _sources(config)
    jobs = group_jobs(find_structures(root, landmarks, seeds, reference))
    if not jobs:
        raise CohortError(f"{root}: no landmarks or seeds found for any T1w image")
    return jobs


def configured_jobs(config):
    """The jobs a workflow configuration names."""
    participants, sessions = labels(config.get("participant_label")), labels(config.get("session_label"))
    return select_jobs(dataset_jobs(config), participants, sessions)


def uncovered_warnings(config, jobs):
    """A warning for each T1w image of the chosen participants and sessions
    that no job segments (no landmarks and no seed for it): a landmark file in
    the wrong folder would otherwise leave its image out unseen."""
    root, landmarks, seeds, _ = _sources(config)
    participants, sessions = labels(config.get("participant_label")), labels(config.get("session_label"))
    covered = {job.t1w for job in jobs.values()}
    return [f"{path}: not segmented: no landmarks for it in {landmarks}/sub-<label>/[ses-<label>/]anat/ "
            f"and no seed in {seeds or root + '/derivatives/seeds.tsv'}"
            for (subject, session, _), path in find_images(root, warn=lambda message: None).items()
            if path not in covered and is_chosen(subject, session, participants, sessions)]


def unclaimed_labelmaps(jobs, out):
    """The labelmaps in out that none of jobs (the dataset's, whichever
    participants are chosen: dataset_jobs) writes: those of a subject, run or
    structure the dataset no longer names, which the group table leaves out."""
    claimed = {job_paths(out, job)["dseg"] for job in jobs.values()}
    found = glob.glob(os.path.join(glob.escape(out), "sub-*", "**", "anat", "*_dseg.nii.gz"), recursive=True)
    return sorted(path for path in found if path not in claimed)


def written_reports(jobs, out):
    """The report.json files of the jobs already segmented in out: what the
    group level summarizes."""
    reports = (job_paths(out, job)["report"] for job in jobs.values())
    return [path for path in reports if os.path.exists(path)]


def _last_error(log):
    """The line of the log that says what went wrong."""
    try:
        lines = [l.strip() for l in open(log, errors="replace") if l.strip()]
    except OSError:
        return "no log"
    errors = [l for l in lines if "error" in l.lower()]
    return (errors or lines or ["empty log"])[-1]


def _earlier_paths(job, out):
    """What an earlier run may have left of this job's results: its
    structures' own files, figures and view, which are not declared outputs
    (Snakemake removes those), and the labelmaps of a grouping the dataset
    had before (a structure segmented alone that is now segmented with
    others, or the other way round)."""
    def own_files(name):  # a structure's files and figures
        return (list(structure_paths(out, job.dir, job.stem, name).values())
                + list(figure_paths(out, job.dir, job.stem, name).values()))

    paths = [view_path(out, job.dir, job.stem, job.desc)]
    for s in job.structures:
        paths += own_files(s.name)
    if len(job.structures) > 1:
        for s in job.structures:
            alone = output_paths(out, job.dir, job.stem, f"_desc-{s.name}")
            paths += [alone["dseg"], alone["lut"], alone["sidecar"],
                      view_path(out, job.dir, job.stem, f"_desc-{s.name}")]
    # The image's job: a joint labelmap from before is this job's, and
    # so are the files of the structures its sidecar lists, also those
    # the dataset no longer has landmarks or a seed for.
    joint = output_paths(out, job.dir, job.stem, "")
    try:
        listed = [s["Name"] for s in json.load(open(joint["sidecar"])).get("Structures", [])]
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        listed = []
    for name in listed:
        if re.fullmatch(LABEL, str(name)):
            paths += own_files(name)
    if len(job.structures) == 1:
        paths += list(joint.values()) + [view_path(out, job.dir, job.stem, "")]
    return paths


def run_segmentation(job, out, log, dynsub, extra_args, bids):
    """Runs `dynsub segment` for one job and gives its results their BIDS names.

    What an earlier run left of the job is removed first (_earlier_paths;
    Snakemake removes the declared outputs). dynsub writes all its outputs
    or none into a private directory beside the final files; they are
    renamed into place only when it succeeded, the job's report last, so a
    failed job leaves nothing of its own.
    """
    outputs = job_paths(out, job)
    for path in _earlier_paths(job, out):
        if os.path.exists(path):
            os.remove(path)
    anat = os.path.dirname(outputs["dseg"])
    os.makedirs(anat, exist_ok=True)
    work = tempfile.mkdtemp(prefix=".work-", dir=anat)
    several = len(job.structures) > 1
    try:
        result = os.path.join(work, "result")
        command = [dynsub, "segment", job.t1w, "--out", result]
        for s in job.structures:
            if s.landmarks:
                command += ["--landmarks", s.landmarks]
        if several:
            for s in job.structures:
                command += ["--name", s.name]
        if any(job.seeds):  # an --init per structure, in its order
            for seed in job.seeds:
                command += ["--init", "seed:%r,%r,%r" % seed if seed else "auto"]
        if job.reference:
            command += ["--reference", job.reference]
            for values in job.reference_labels:
                command += ["--reference-label", ",".join(map(str, values))]
        command += shlex.split(extra_args)
        with open(log, "w") as f:
            f.write("$ " + shlex.join(command) + "\n")
            f.flush()
            status = subprocess.run(command, stdout=f, stderr=subprocess.STDOUT).returncode
        if status != 0:
            raise RuntimeError(f"{job.name}: dynsub segment failed (exit {status}): {_last_error(log)} (log: {log})")

        # Each structure's own files: DIR/NAME/ for several, DIR/ for one.
        meshes = []
        for s in job.structures:
            own = os.path.join(result, s.name) if several else result
            paths = structure_paths(out, job.dir, job.stem, s.name)
            os.replace(f"{own}/surface.vtp", paths["surface"])
            os.replace(f"{own}/convergence.csv", paths["convergence"])
            if several:
                os.replace(f"{own}/report.json", paths["report"])
            for name, path in figure_paths(out, job.dir, job.stem, s.name).items():
                if os.path.exists(f"{own}/{name}.png"):  # rendered when an X server could be had
                    os.makedirs(os.path.dirname(path), exist_ok=True)
                    os.replace(f"{own}/{name}.png", path)
            meshes.append(f"{own}/control_mesh.obj")

        if several:
            os.replace(f"{result}/dseg.tsv", outputs["lut"])
        else:
            with open(outputs["lut"], "w") as f:
                f.write(f"index\tname\tcolor\n1\t{job.structures[0].name}\t{LABEL_COLOR}\n")
        sources = [f"bids:raw:{_relative(job.t1w, bids)}"]
        sources += [f"bids:raw:{_relative(s.landmarks, bids)}" for s in job.structures if s.landmarks]
        names = ", ".join(s.name for s in job.structures)
        sidecar = {
            "Description": f"{names} segmented by dynamic Catmull-Clark subdivision surfaces (dynsub segment)"
                           + (", together so that they do not overlap" if several else "")
                           + "".join(f", {s.name} from a seed click" for s in job.structures
                                     if s.seed and not s.landmarks),
            "Sources": sources,
            "SpatialReference": f"bids:raw:{_relative(job.t1w, bids)}",
            "Report": os.path.basename(outputs["report"]),
            "Structures": [{"Index": i + 1, "Name": s.name,
                            **{k.capitalize(): os.path.basename(p)
                               for k, p in structure_paths(out, job.dir, job.stem, s.name).items()},
                            **({"SeedLPS": list(s.seed)} if s.seed else {})}
                           for i, s in enumerate(job.structures)],
        }
        with open(outputs["sidecar"], "w") as f:
            json.dump(sidecar, f, indent=2)
            f.write("\n")
        os.replace(f"{result}/dseg.nii.gz" if several else f"{result}/labelmap.nii.gz", outputs["dseg"])
        try:  # the QC page's view is an extra: without it the page says so, and the job stands
            script = qc_view.view_script(job.name, job.t1w, outputs["dseg"], meshes, dynsub, work)
            view = view_path(out, job.dir, job.stem, job.desc)
            os.makedirs(os.path.dirname(view), exist_ok=True)
            write_by_rename(view, script)
        except (OSError, ValueError, subprocess.CalledProcessError) as error:
            with open(log, "a") as f:
                f.write(f"QC view not written: {error}\n")
        os.replace(f"{result}/report.json", outputs["report"])
    finally:
        shutil.rmtree(work, ignore_errors=True)


GROUP_COLUMNS = {
    "participant_id": "The subject (sub-<label>).",
    "session_id": "The session (ses-<label>), or n/a.",
    "structure": "The structure (the desc- entity of its files).",
    "status": "ok, failed (see message and the job's log) or not run.",
    "volume_mm3": "Volume of the labelmap, mm^3.",
    "dice": "Dice against the reference labelmap, where there is one.",
    "mean_surface_distance_mm": "Mean symmetric surface distance to the reference, mm.",
    "hd95_mm": "95th percentile of the surface distances to the reference, mm.",
    "control_vertices": "Control vertices of the final surface.",
    "iterations": "Time steps of the evolution.",
    "seconds": "Wall-clock seconds of the structure's segmentation (its last pass, when segmented with others).",
    "warnings": "dynsub's warnings (a collapse, a leak, a cut by the image's side, landmarks off edges), "
                "separated by '; '.",
    "trust_flags": "Why not to trust the result (report.json's trust flags: one_click, collapsed, "
                   "small, atlas_clicks_apart, moved_from_atlas, moved_to_click, cut_by_image_side, leaked), separated by spaces, "
                   "or n/a.",
    "message": "Why a job failed.",
    "dseg": "The labelmap holding the structure, relative to the dataset root.",
    "index": "The structure's value in that labelmap (its dseg.tsv's index).",
    "t1w": "The T1w image segmented, relative to the raw dataset's root.",
}


def group_rows(jobs, out):
    """One row per structure, in the jobs' order. A structure segmented with
    others is scored by its share of their labelmap (the run's report), which
    is what the dseg holds; its own report gives the rest."""
    rows = []
    for key in sorted(jobs):
        job = jobs[key]
        paths = job_paths(out, job)
        several = len(job.structures) > 1
        complete = all(os.path.exists(p) for p in paths.values())
        joint = json.load(open(paths["report"]))["structures"] if complete and several else None
        log = log_path(out, job.dir, job.stem, job.desc)
        for index, structure in enumerate(job.structures):
            row = {c: "n/a" for c in GROUP_COLUMNS}
            row.update(participant_id=f"sub-{job.subject}",
                       session_id=f"ses-{job.session}" if job.session else "n/a", structure=structure.name,
                       t1w=os.path.join(job.dir, "anat", os.path.basename(job.t1w)))
            row["job"] = job  # not a column: for the QC page (qc_report.py)
            if complete:
                report = json.load(open(structure_paths(out, job.dir, job.stem, structure.name)["report"]))
                row["report"] = report  # not a column either
                row.update(status="ok", dseg=_relative(paths["dseg"], out), index=str(index + 1),
                           warnings="; ".join(report.get("warnings", [])) or "n/a",
                           trust_flags=" ".join(f["name"] for f in report.get("trust", {}).get("flags", [])) or "n/a")
                scores = dict(report)
                if joint:
                    scores["volume_mm3"] = joint[index]["joint_volume_mm3"]
                    for column in ("dice", "mean_surface_distance_mm", "hd95_mm"):
                        scores[column] = joint[index].get("joint", {}).get(column, "n/a")
                for column in ("volume_mm3", "dice", "mean_surface_distance_mm", "hd95_mm", "control_vertices",
                               "iterations", "seconds"):
                    if column in scores:
                        value = scores[column]
                        row[column] = f"{value:.4f}" if isinstance(value, float) else str(value)
            elif os.path.exists(log):
                row.update(status="failed", message=_last_error(log))
            else:
                row.update(status="not run")
            rows.append(row)
    return rows


def write_group_table(jobs, out, table):
    """segmentations.tsv (and its JSON column descriptions): one row per structure."""
    rows = group_rows(jobs, out)
    os.makedirs(os.path.dirname(table) or ".", exist_ok=True)
    temporary = table + ".tmp"
    with open(temporary, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(GROUP_COLUMNS), delimiter="\t", lineterminator="\n")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: str(row[k]).replace("\t", " ").replace("\n", " ") for k in GROUP_COLUMNS})
    os.replace(temporary, table)
    with open(table.removesuffix(".tsv") + ".json", "w") as f:
        json.dump({c: {"Description": d} for c, d in GROUP_COLUMNS.items()}, f, indent=2)
        f.write("\n")
    return rows


# What a BIDS validator run over the derivatives should not judge: the
# workflow's own files and the outputs the derivatives specification has no
# rule for.
BIDSIGNORE = ["logs/", "work/", "report.html", "segmentations.tsv", "segmentations.json", "*_surface.vtp",
              "*_report.json", "*_convergence.csv", "figures/", "viewer/"]


def _write_if_changed(path, text):
    """Writes text by a rename, and only when it differs from the file's, so
    that runs of several participants at once can each write it and a rerun
    leaves it untouched."""
    try:
        if open(path, encoding="utf-8").read() == text:
            return
    except OSError:
        pass
    write_by_rename(path, text)


def write_by_rename(path, text):
    """Writes text to a temporary file beside path, then renames it into
    place: readers see the old file or the whole new one, never a part."""
    temporary = f"{path}.{os.getpid()}.tmp"
    with open(temporary, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(temporary, path)


def write_bidsignore(path):
    _write_if_changed(path, "\n".join(BIDSIGNORE) + "\n")


def write_dataset_description(path, version, bids):
    description = {
        "Name": "DynSub segmentations",
        "BIDSVersion": "1.9.0",
        "DatasetType": "derivative",
        "GeneratedBy": [{"Name": "DynSub", "Version": version,
                         "Description": "dynamic Catmull-Clark subdivision surfaces (dynsub segment)"}],
        "DatasetLinks": {"raw": pathlib.Path(os.path.abspath(bids)).as_uri()},  # a space is %20 in a URI
    }
    _write_if_changed(path, json.dumps(description, indent=2) + "\n")
