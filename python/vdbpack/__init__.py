# SPDX-License-Identifier: Apache-2.0
"""vdbpack: placeholder."""
