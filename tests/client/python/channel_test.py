"""channel_target / channel_options (client/python/fovea_client/channel.py):
the same targets as the C++ client's ChannelTarget. Exits 77 (ctest
SKIP_RETURN_CODE) when the client cannot be imported."""

import json
import sys
import unittest

try:
    from fovea_client.channel import channel_options, channel_target
except ImportError as e:
    print(f"skipped: {e}")
    sys.exit(77)


class ChannelTargetTest(unittest.TestCase):
    def test_one_target_passes_unchanged(self):
        for target in ["127.0.0.1:50051", "fovea:50051",
                       "dns:///fovea.default.svc:50051",
                       "ipv4:10.0.0.1:1,10.0.0.2:2"]:
            self.assertEqual(channel_target(f" {target} "), target)

    def test_list_of_ip_literals_becomes_one_address_list(self):
        self.assertEqual(channel_target("127.0.0.1:5001, 127.0.0.1:5002"),
                         "ipv4:127.0.0.1:5001,127.0.0.1:5002")
        self.assertEqual(channel_target("[::1]:5001,[fd00::5]:5002"),
                         "ipv6:[::1]:5001,[fd00::5]:5002")

    def test_bad_lists_are_refused_naming_the_entry(self):
        cases = {
            "": "empty target",
            "127.0.0.1:1,,127.0.0.1:2": "entry 2",
            "127.0.0.1:1,": "is empty",
            "127.0.0.1:1,fovea-b:50051": "dns:///fovea-b:50051",
            "127.0.0.1:0,127.0.0.1:2": "want 1..65535",
            "::1:5,127.0.0.1:2": "[IPV6]:PORT",
            "[::1]:5,127.0.0.1:2": "mixes IPv4 and IPv6",
            "127.0.0.1:5,127.0.0.1:5": "repeats",
        }
        for servers, text in cases.items():
            with self.assertRaises(ValueError, msg=servers) as caught:
                channel_target(servers)
            self.assertIn(text, str(caught.exception), servers)


class ChannelOptionsTest(unittest.TestCase):
    def test_balanced_config_health_checks_and_retries(self):
        options = dict(channel_options(1 << 20, max_attempts=3))
        config = json.loads(options["grpc.service_config"])
        self.assertEqual(config["loadBalancingConfig"], [{"round_robin": {}}])
        self.assertEqual(config["healthCheckConfig"],
                         {"serviceName": "fovea.v1.Perception"})
        policy = config["methodConfig"][0]["retryPolicy"]
        self.assertEqual(policy["maxAttempts"], 3)
        self.assertEqual(policy["retryableStatusCodes"], ["UNAVAILABLE"])
        self.assertEqual(options["grpc.per_rpc_retry_buffer_size"], 1 << 20)

    def test_probe_config_neither_checks_health_nor_retries(self):
        config = json.loads(dict(channel_options(
            1 << 20, balanced=False))["grpc.service_config"])
        self.assertNotIn("healthCheckConfig", config)
        self.assertNotIn("methodConfig", config)

    def test_max_attempts_is_named(self):
        with self.assertRaisesRegex(ValueError, "max_attempts"):
            channel_options(1 << 20, max_attempts=6)


if __name__ == "__main__":
    unittest.main()
