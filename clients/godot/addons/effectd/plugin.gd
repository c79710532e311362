# Enabling the addon in the editor registers EffectdClient as a node type (Create Node dialog).
tool
extends EditorPlugin

func _enter_tree():
	add_custom_type("EffectdClient", "Node", preload("effectd_client.gd"), null)

func _exit_tree():
	remove_custom_type("EffectdClient")
