# SPDX-License-Identifier: Apache-2.0
"""
rclpy nodes: thin adapters from messages to model calls and back.

Each node lives in its own module with a ``main`` (the console script). Importing this
package does not import rclpy; importing a node module does.
"""
