#!/usr/bin/python3
"""Prints a Slurm job's state as Snakemake's --cluster-status expects:
running, success or failed.

scontrol knows a job until MinJobAge after it ends (300 s by default);
after that, sacct, where the cluster keeps accounting. A job neither knows
is reported failed, so that Snakemake does not wait for it forever.
"""
import subprocess
import sys

RUNNING = {"PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "SUSPENDED", "REQUEUED", "RESIZING", "STAGE_OUT",
           "SIGNALING", "REQUEUE_FED", "REQUEUE_HOLD", "SPECIAL_EXIT", "STOPPED"}


def state(job):
    result = subprocess.run(["scontrol", "show", "job", "-o", job], capture_output=True, text=True)
    for field in result.stdout.split():
        if field.startswith("JobState="):
            return field.split("=", 1)[1]
    result = subprocess.run(["sacct", "-j", job, "-X", "-n", "-P", "-o", "State"], capture_output=True, text=True)
    # One line per job, e.g. "CANCELLED by 0": the state is its first word.
    words = result.stdout.split()
    return words[0] if result.returncode == 0 and words else None


job_state = state(sys.argv[1])
print("success" if job_state == "COMPLETED" else "running" if job_state in RUNNING else "failed")
