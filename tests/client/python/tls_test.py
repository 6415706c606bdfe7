"""The Python client against fovea-server with mutual TLS: certificates
made with openssl in a temporary folder; a client with the CA and a client
certificate is served, one without the certificate is not, and bad
arguments are refused. Exits 77 (ctest SKIP_RETURN_CODE) without the
Python modules or openssl.

    tls_test.py --server_binary build/bin/fovea-server --models_dir models
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

try:
    import grpc
    from fovea_client import FoveaClient
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)
if shutil.which("openssl") is None:
    print("skipped: no openssl")
    sys.exit(77)

import server_process  # noqa: E402  (beside this script)

ARGS = None  # set in __main__


def make_certificates(folder):
    def run(*args):
        subprocess.run(["openssl", *args], cwd=folder, check=True,
                       capture_output=True)
    run("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key",
        "-out", "ca.pem", "-days", "1", "-subj", "/CN=fovea-test-ca")
    for who in ("server", "client"):
        run("req", "-newkey", "rsa:2048", "-nodes", "-keyout", f"{who}.key",
            "-out", f"{who}.csr", "-subj", f"/CN={who}")
        with open(os.path.join(folder, f"{who}.ext"), "w") as f:
            f.write("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
        run("x509", "-req", "-in", f"{who}.csr", "-CA", "ca.pem", "-CAkey",
            "ca.key", "-CAcreateserial", "-out", f"{who}.pem", "-days", "1",
            "-extfile", f"{who}.ext")


def read(folder, name):
    with open(os.path.join(folder, name), "rb") as f:
        return f.read()


class TlsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="fovea_tls_")
        make_certificates(cls.folder)
        cls.ca = read(cls.folder, "ca.pem")
        cls.cert = read(cls.folder, "client.pem")
        cls.key = read(cls.folder, "client.key")

        def is_serving(target):
            with FoveaClient(target, tls_ca=cls.ca, tls_cert=cls.cert,
                             tls_key=cls.key) as client:
                try:
                    return client.health(timeout=1.0) == "SERVING"
                except grpc.RpcError:
                    return False

        try:
            cls.server, cls.target = server_process.start_serving(
                [ARGS.server_binary, "--metrics_listen=",
                 f"--models_dir={ARGS.models_dir}", "--concurrency=1",
                 f"--tls_cert={cls.folder}/server.pem",
                 f"--tls_key={cls.folder}/server.key",
                 f"--tls_client_ca={cls.folder}/ca.pem"],
                is_serving)
        except AssertionError:
            shutil.rmtree(cls.folder, ignore_errors=True)
            raise

    @classmethod
    def tearDownClass(cls):
        server_process.stop(cls.server)
        shutil.rmtree(cls.folder, ignore_errors=True)

    def test_client_with_a_certificate_is_served(self):
        with FoveaClient(self.target, tls_ca=self.ca, tls_cert=self.cert,
                         tls_key=self.key) as client:
            capabilities = client.capabilities(timeout=10)
        self.assertIn("32FC1", capabilities.depth_encodings)

    def test_client_without_a_certificate_is_refused(self):
        with FoveaClient(self.target, tls_ca=self.ca) as client:
            with self.assertRaises(grpc.RpcError):
                client.capabilities(timeout=5)
        with FoveaClient(self.target) as client:  # plaintext
            with self.assertRaises(grpc.RpcError):
                client.capabilities(timeout=5)

    def test_half_a_client_certificate_is_a_value_error(self):
        with self.assertRaises(ValueError):
            FoveaClient(self.target, tls_ca=self.ca, tls_cert=self.cert)
        with self.assertRaises(ValueError):
            FoveaClient(self.target, tls_cert=self.cert, tls_key=self.key)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--server_binary", required=True)
    parser.add_argument("--models_dir", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest)
