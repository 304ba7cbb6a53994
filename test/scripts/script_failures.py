"""What every script test expects of bad input: a non-zero exit and a one-line message that
names what is wrong, not a Python traceback."""


class CleanFailureAssertions:
    """Mixin for unittest.TestCase."""

    def assertFailsCleanly(self, process, *texts):
        """A non-zero exit with a one-line message holding each text, not a traceback."""
        self.assertNotEqual(process.returncode, 0)
        for text in texts:
            self.assertIn(str(text), process.stderr)
        self.assertNotIn("Traceback", process.stderr)
        self.assertEqual(len(process.stderr.strip().splitlines()), 1, process.stderr)
