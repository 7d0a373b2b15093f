#!/usr/bin/python3
# Debian's Python, the one Snakemake is installed for (read_job_properties).
"""Submits one Snakemake job script (the last argument) with sbatch and
prints its Slurm job id, as Snakemake's --cluster expects.

The job's rule, threads and resources come from the job script: cpus, memory
(mem_mb), time limit (runtime, minutes), and the site's partition and account
(slurm_partition, slurm_account: the profile's default-resources), each
passed only when set.
"""
import os
import subprocess
import sys

from snakemake.utils import read_job_properties

jobscript = sys.argv[-1]
job = read_job_properties(jobscript)
resources = job.get("resources", {})
command = ["sbatch", "--parsable", f"--job-name=dynsub-{job['rule']}", f"--cpus-per-task={job.get('threads', 1)}",
           "--output=slurm-logs/%j.log"]
for key, flag in (("mem_mb", "--mem"), ("runtime", "--time"), ("slurm_partition", "--partition"),
                  ("slurm_account", "--account")):
    if resources.get(key) not in (None, ""):
        command.append(f"{flag}={resources[key]}")
os.makedirs("slurm-logs", exist_ok=True)
result = subprocess.run(command + [jobscript], capture_output=True, text=True)
if result.returncode != 0:
    sys.exit(f"sbatch failed (exit {result.returncode}): {result.stderr.strip()}\n  {' '.join(command)}")
print(result.stdout.strip().split(";")[0])  # "id" or "id;cluster"
