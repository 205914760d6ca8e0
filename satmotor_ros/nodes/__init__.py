# SPDX-License-Identifier: Apache-2.0
"""rclpy nodes: thin adapters from messages to the model and the plant."""
