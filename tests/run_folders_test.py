#!/usr/bin/python3
"""Run folders and their provenance records (scripts/orbed, scripts/provenance.py; docs/runs.md).

  run_folders_test.py records   provenance.py on a run folder made here: what `start` records
                                (hashes checked with hashlib), what `finish` adds, and that
                                `verify` finds a changed output, a missing one and a changed
                                configuration file, and passes an untouched folder
                                and scripts/settings.py: --config and --set merged in order into
                                each reader's overlay, what is not a setting refused, and the
                                readers' --check-config naming a bad key with its file and line
  run_folders_test.py studies   three small studies (`scripts/orbed study --users 1 --trials 1
                                --setup-users 1 --targets 1`) started together in one logs folder,
                                then the same study alone: four distinct folders, each user's run
                                in its own folder inside its study with its own record, and the
                                tables of the three equal to those of the one alone, byte for byte;
                                `scripts/orbed verify` passes each and fails a tampered copy

Environment: ORBED_BUILD_DIR, the build whose executables run (the studies).
"""
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROVENANCE = os.path.join(ROOT, "scripts", "provenance.py")
ORBED = os.path.join(ROOT, "scripts", "orbed")
TABLES = ("alignment_trials.csv", "alignment_means.csv", "alignment_groups.csv", "landmark_validation.csv",
          "setup_joints.csv", "setup_times.csv", "setup_docking.csv", "tables.json")


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def provenance(*args, env=None):
    return subprocess.run(["/usr/bin/python3", PROVENANCE, *args], capture_output=True, text=True,
                          env=env)


class Records(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="orbed_records_")
        self.addCleanup(shutil.rmtree, self.tmp)
        # A launch file that includes another and gives a process an existing file and a missing one.
        self.config = os.path.join(self.tmp, "person.yaml")
        with open(self.config, "w") as f:
            f.write("user: {depth_bias_std_m: 0.02}\n")
        with open(os.path.join(self.tmp, "inner.yaml"), "w") as f:
            f.write("name: inner\ngroups:\n  - name: g\n    host: hostC\n    processes:\n"
                    "      - {name: a, command: true, args: [--config, '${CONFIG_UNDER_TEST}']}\n")
        self.launch = os.path.join(self.tmp, "outer.yaml")
        with open(self.launch, "w") as f:
            f.write("name: outer\ninclude: [inner.yaml]\nplacement: {a: hostB}\ngroups:\n"
                    "  - name: h\n    processes:\n      - {name: b, command: true, args: [/no/such/file]}\n")
        self.run_dir = os.path.join(self.tmp, "20261204T000000Z-abcdef")
        os.mkdir(self.run_dir)
        self.env = dict(os.environ, CONFIG_UNDER_TEST=self.config)

    def start(self):
        done = provenance("start", self.run_dir, "--kind", "launch", "--launch", self.launch,
                          "--setting", "ORBED_USER_SEED=7", "--setting", "ORBED_TRIALS=2", "--",
                          "scripts/orbed", "launch", "outer.yaml", env=self.env)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(self.run_dir, "provenance.json")) as f:
            return json.load(f)

    def test_start_records_the_inputs(self):
        record = self.start()
        self.assertEqual(record["format"], "orbed.provenance/1")
        self.assertEqual(record["run"], "20261204T000000Z-abcdef")
        self.assertEqual(record["command_line"], ["scripts/orbed", "launch", "outer.yaml"])
        self.assertEqual(record["settings"], {"ORBED_USER_SEED": "7", "ORBED_TRIALS": "2"})
        self.assertEqual(record["placed_on_hosts"], ["hostB", "hostC"])
        self.assertIsNone(record["ended_utc"])
        hashed = {c["path"]: c["sha256"] for c in record["config_files"]}
        # The launch file, the file it includes and the existing file a process is given; not the
        # missing one.
        self.assertEqual(set(hashed), {self.launch, os.path.join(self.tmp, "inner.yaml"), self.config})
        for path, sha in hashed.items():
            self.assertEqual(sha, digest(path), path)
        head = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True)
        if head.returncode == 0:
            self.assertEqual(record["git"]["commit"], head.stdout.strip())
            self.assertIn(record["git"]["dirty"], (True, False))
        with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
            self.assertIn("VERSION " + record["orbed_version"], f.read())

    def test_finish_hashes_the_outputs_and_verify_finds_changes(self):
        self.start()
        with open(os.path.join(self.run_dir, "results.json"), "w") as f:
            f.write('{"status": "ok"}\n')
        with open(os.path.join(self.run_dir, "run.lcmlog"), "wb") as f:
            f.write(bytes(range(256)) * 4)
        done = provenance("finish", self.run_dir, "--exit-code", "3")
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(self.run_dir, "provenance.json")) as f:
            record = json.load(f)
        self.assertEqual(record["exit_code"], 3)
        self.assertIsNotNone(record["ended_utc"])
        outputs = {o["path"]: (o["sha256"], o["bytes"]) for o in record["outputs"]}
        self.assertEqual(outputs, {
            "results.json": (digest(os.path.join(self.run_dir, "results.json")), 17),
            "run.lcmlog": (digest(os.path.join(self.run_dir, "run.lcmlog")), 1024)})

        untouched = provenance("verify", self.run_dir)
        self.assertEqual(untouched.returncode, 0, untouched.stdout)
        self.assertIn("nothing differs", untouched.stdout)

        with open(os.path.join(self.run_dir, "results.json"), "a") as f:
            f.write(" ")
        os.remove(os.path.join(self.run_dir, "run.lcmlog"))
        with open(self.config, "a") as f:
            f.write("# edited after the run\n")
        changed = provenance("verify", self.run_dir)
        self.assertEqual(changed.returncode, 1, changed.stdout)
        self.assertIn("changed since the run: results.json", changed.stdout)
        self.assertIn("missing: run.lcmlog", changed.stdout)
        self.assertIn("configuration changed in the source tree since the run: " + self.config, changed.stdout)
        self.assertIn("2 difference(s)", changed.stdout)

    def test_an_unfinished_run_is_said_to_be(self):
        self.start()
        done = provenance("verify", self.run_dir)
        self.assertEqual(done.returncode, 1)
        self.assertIn("not finished", done.stdout)

    def test_a_record_that_leads_elsewhere_or_lacks_keys_is_a_difference_not_a_crash(self):
        record = self.start()
        for change, said in ((lambda r: r.update(runs=[".."]), "runs: expected names of folders inside"),
                             (lambda r: r.update(outputs=[{"path": "/etc/passwd", "sha256": "0"}]),
                              "outputs: expected {path inside the run folder"),
                             (lambda r: r.pop("run"), "run: expected a str"),
                             (lambda r: r.update(config_files="x"), "config_files: expected a list")):
            broken = dict(record)
            change(broken)
            with open(os.path.join(self.run_dir, "provenance.json"), "w") as f:
                json.dump(broken, f)
            done = provenance("verify", self.run_dir)
            self.assertEqual(done.returncode, 1, done.stderr)
            self.assertIn(said, done.stdout)
            self.assertEqual(done.stderr, "")
        with open(os.path.join(self.run_dir, "provenance.json"), "wb") as f:
            f.write(b"\xff\xfe{")
        done = provenance("verify", self.run_dir)
        self.assertEqual((done.returncode, done.stderr), (1, ""))
        self.assertIn("cannot be read as JSON", done.stdout)

    def test_a_folder_without_a_record_is_refused(self):
        done = provenance("verify", self.run_dir)
        self.assertEqual(done.returncode, 1)
        self.assertIn("provenance.json", done.stdout)


class Settings(unittest.TestCase):
    """scripts/settings.py, and the readers' --check-config on what it writes."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="orbed_settings_")
        self.addCleanup(shutil.rmtree, self.tmp)
        self.bin = os.path.join(os.environ.get("ORBED_BUILD_DIR", os.path.join(ROOT, "build")), "bin")

    def settings(self, *args):
        return subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "settings.py"),
                               os.path.join(self.tmp, "out"), *args], capture_output=True, text=True)

    def test_files_and_sets_merge_in_order_into_each_readers_overlay(self):
        config = os.path.join(self.tmp, "mine.yaml")
        with open(config, "w") as f:
            f.write("user:\n  direct_view: {depth_bias_fraction_std: 0.02}\n  seed: 4\nassistant:\n  seed: 9\n")
        done = self.settings("--config", config, "--set", "user.direct_view.depth_bias_fraction_std=0.05",
                             "--set", "slam.drift_m_per_m=[0.001, 0.0, 0.0]")
        self.assertEqual(done.returncode, 0, done.stderr)
        out = os.path.join(self.tmp, "out")
        self.assertEqual(done.stdout.splitlines(), [f"hmd_config={out}/hmd.yaml",
                                                    f"assistant_config={out}/assistant.yaml"])
        with open(os.path.join(out, "settings.json")) as f:
            merged = json.load(f)
        self.assertEqual(merged["settings"], {"user.direct_view.depth_bias_fraction_std": 0.05, "user.seed": 4,
                                              "assistant.seed": 9, "slam.drift_m_per_m": [0.001, 0.0, 0.0]})
        self.assertEqual(merged["from"]["user.seed"], f"--config {config}")
        self.assertEqual(merged["from"]["user.direct_view.depth_bias_fraction_std"],
                         "--set user.direct_view.depth_bias_fraction_std=0.05")
        import yaml
        with open(os.path.join(out, "hmd.yaml")) as f:
            self.assertEqual(yaml.safe_load(f), {"user": {"direct_view": {"depth_bias_fraction_std": 0.05}, "seed": 4},
                                                 "slam": {"drift_m_per_m": [0.001, 0.0, 0.0]}})
        with open(os.path.join(out, "assistant.yaml")) as f:
            self.assertEqual(yaml.safe_load(f), {"assistant": {"seed": 9}})

    def test_what_is_not_a_setting_is_refused_before_anything_is_written(self):
        done = self.settings("--set", "robot.speed=2")
        self.assertEqual(done.returncode, 2)
        self.assertIn("--set robot.speed=2: robot.speed: 'robot' is not a section", done.stderr)
        done = self.settings("--set", "user=3")
        self.assertEqual(done.returncode, 2)
        self.assertIn("expected a key inside the section", done.stderr)
        self.assertEqual(self.settings("--set", "novalue").returncode, 2)
        listed = os.path.join(self.tmp, "list.yaml")
        with open(listed, "w") as f:
            f.write("- 1\n")
        self.assertIn("expected a mapping of sections", self.settings("--config", listed).stderr)
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "out")))

    def test_the_readers_check_every_key(self):
        hmd = os.path.join(self.bin, "orbed-hmd")
        if not os.path.exists(hmd):
            self.skipTest("orbed-hmd is not built")
        self.assertEqual(self.settings("--set", "user.direct_view.depth_bias_fraction_std=0.05").returncode, 0)
        overlay = os.path.join(self.tmp, "out", "hmd.yaml")
        good = subprocess.run([hmd, "--check-config", "--config", overlay], capture_output=True, text=True)
        self.assertEqual(good.returncode, 0, good.stderr)
        self.assertEqual(self.settings("--set", "user.direct_view.depth_bias_fraction_sd=0.05").returncode, 0)
        bad = subprocess.run([hmd, "--check-config", "--config", overlay], capture_output=True, text=True)
        self.assertEqual(bad.returncode, 2)
        self.assertIn(f"{overlay}:4", bad.stderr)
        self.assertIn("depth_bias_fraction_sd", bad.stderr)
        self.assertEqual(self.settings("--set", "assistant.headset.lateral_noise_arcmin=-1").returncode, 0)
        assistant = subprocess.run([os.path.join(self.bin, "orbed-assistant"), "--check-config", "--config",
                                    os.path.join(self.tmp, "out", "assistant.yaml")], capture_output=True, text=True)
        self.assertEqual(assistant.returncode, 2)
        self.assertIn("lateral_noise_arcmin", assistant.stderr)


class Studies(unittest.TestCase):
    # The assistant's shipped value set again: the setting reaches the set-up runs (and not the
    # ViRAAl runs, whose launch has no assistant) without changing a number.
    ARGS = ["study", "--users", "1", "--trials", "1", "--setup-users", "1", "--targets", "1",
            "--set", "assistant.headset.lateral_noise_arcmin=4.0"]

    def test_studies_started_together_are_each_their_own(self):
        logs = tempfile.mkdtemp(prefix="orbed_studies_")
        self.addCleanup(shutil.rmtree, logs)
        env = dict(os.environ, ORBED_LOGS_DIR=logs)
        together = [subprocess.Popen([ORBED, *self.ARGS], env=env, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True) for _ in range(3)]
        outputs = [p.communicate(timeout=1800)[0] for p in together]
        for p, out in zip(together, outputs):
            self.assertEqual(p.returncode, 0, out[-3000:])
        alone = subprocess.run([ORBED, *self.ARGS], env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=1800)
        self.assertEqual(alone.returncode, 0, alone.stdout[-3000:])

        studies = sorted(d for d in os.listdir(logs) if d.startswith("study-"))
        self.assertEqual(len(studies), 4, os.listdir(logs))
        records = {}
        for study in studies:
            folder = os.path.join(logs, study)
            with open(os.path.join(folder, "provenance.json")) as f:
                records[study] = json.load(f)
            self.assertEqual(records[study]["kind"], "study")
            self.assertEqual(records[study]["exit_code"], 0)
            self.assertEqual(sorted(records[study]["runs"]), ["setup-u1", "viraal-u1"])
            for run in ("viraal-u1", "setup-u1"):
                with open(os.path.join(folder, run, "provenance.json")) as f:
                    user = json.load(f)
                self.assertEqual(user["part_of"], study)
                self.assertEqual(user["arguments"]["user_seed"], "1")
                self.assertEqual(user["arguments"]["run_id"], f"study-s1-{run.split('-')[0]}-u1"
                                 if run.startswith("setup") else "study-s1-u1")
                self.assertEqual(user["exit_code"], 0)
            with open(os.path.join(folder, "setup-u1", "provenance.json")) as f:
                self.assertEqual(json.load(f)["arguments"]["assistant_config"],
                                 os.path.join(folder, "setup-u1", "settings", "assistant.yaml"))
            with open(os.path.join(folder, "viraal-u1", "provenance.json")) as f:
                self.assertNotIn("assistant_config", json.load(f)["arguments"])
            # Results files name the record beside them.
            with open(os.path.join(folder, "viraal-u1", "results.json")) as f:
                self.assertEqual(json.load(f)["provenance"], "provenance.json")
            with open(os.path.join(folder, "setup-u1", "setup_results.json")) as f:
                self.assertEqual(json.load(f)["provenance"], "provenance.json")
            with open(os.path.join(folder, "report.html")) as f:
                self.assertIn(records[study]["git"]["commit"] or "unknown commit", f.read())
        # The one alone is the last started.
        last = max(studies, key=lambda s: records[s]["started_utc"])
        for study in studies:
            for name in TABLES:
                with open(os.path.join(logs, study, name), "rb") as a, \
                        open(os.path.join(logs, last, name), "rb") as b:
                    self.assertEqual(a.read(), b.read(), f"{study}/{name} differs from {last}/{name}")

        verified = subprocess.run([ORBED, "verify", os.path.join(logs, last)], env=env,
                                  capture_output=True, text=True)
        self.assertEqual(verified.returncode, 0, verified.stdout + verified.stderr)
        self.assertIn("8 files identical", verified.stdout)
        # A number changed in a user's results: the tables made again differ, and the hash says so.
        results = os.path.join(logs, last, "setup-u1", "setup_results.json")
        with open(results) as f:
            doc = json.load(f)
        doc["setups"][0]["reached_deg"][0] += 1.0
        with open(results, "w") as f:
            json.dump(doc, f, indent=2)
        tampered = subprocess.run([ORBED, "verify", os.path.join(logs, last)], env=env,
                                  capture_output=True, text=True)
        self.assertEqual(tampered.returncode, 1, tampered.stdout)
        self.assertIn("changed since the run: setup_results.json", tampered.stdout)
        self.assertIn("setup_joints.csv: differs from the tables made again", tampered.stdout)
        # The analysis made again from the changed joints: its tables differ too.
        self.assertIn("tables.json: differs from the tables made again", tampered.stdout)


if __name__ == "__main__":
    which = sys.argv.pop(1) if len(sys.argv) > 1 else "records"
    cases = {"records": [Records, Settings], "studies": [Studies]}[which]
    suite = unittest.TestSuite(unittest.TestLoader().loadTestsFromTestCase(c) for c in cases)
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    sys.exit(0 if result.wasSuccessful() else 1)
